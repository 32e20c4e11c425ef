"""Complex modes of a cable with dampers by finite elements: the quadratic eigenproblem (K + s C + s² M) v = 0.

The cable's finite-element model (:mod:`.fem_assembly`, Hermite beam
elements, point masses and springs, the sag-extensibility term) gets a node
at each damper; the damper's spring and moving mass join K and M there, its
dashpot is the only entry of C. The quadratic problem is solved through its
companion linearisation

    [ 0   I ] [v ]       [ I  0 ] [v ]
    [-K  -C ] [sv]  = s  [ 0  M ] [sv]

with LAPACK's generalized eigensolver (dense; a few hundred elements).
Each mode is a complex-conjugate pair; the one with Im s > 0 is kept, and
modes are ordered by |s|. A mode's frequency is |s|/2π and its damping
ratio ζ = −Re(s)/|s|.

This is the independent reference of the exact complex solver: the same
physics, another discretisation. It converges as the mesh is refined
(O(h⁴) in the frequencies of the beam elements).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from ..errors import ComputationError
from ..model import Attachment, Cable, Damper
from .fem_assembly import fe_matrices

__all__ = ["ComplexModes", "fe_complex_modes"]


@dataclass(frozen=True)
class ComplexModes:
    """Complex eigenvalues s (Im s > 0, by |s|), their frequencies |s|/2π (Hz) and damping ratios −Re(s)/|s|."""

    s: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray


def fe_complex_modes(cable: Cable, attachments: Sequence[Attachment], dampers: Sequence[Damper], tension: float,
                     n_modes: int, n_elements: int = 200, tension_model: str = "uniform",
                     grading: float = 0.0) -> ComplexModes:
    """The lowest ``n_modes`` complex modes of the cable with its attachments and dampers (finite elements).

    Parameters
    ----------
    cable, attachments, tension, n_elements, tension_model, grading :
        As :func:`~stcs_ident.forward.fem_assembly.fe_matrices` (``grading`` refines the boundary layers
        of a taut beam at restrained ends).
    dampers : sequence of Damper
        Each strictly inside the span; one at the position of an attachment shares its node.
    n_modes : int

    Returns
    -------
    ComplexModes
    """
    for d in dampers:
        if not 0 < d.position < cable.length:
            from ..errors import ModelError

            raise ModelError(f"position {d.position} m is outside the span (0, {cable.length}) m",
                             field=f"damper[{d.name}].position")
    # A damper's spring and moving mass are an attachment's; a node at each damper.
    nodes = [Attachment(f"damper {d.name}", d.position, d.mass, d.stiffness) for d in dampers]
    model = fe_matrices(cable, list(attachments) + nodes, tension, n_elements, tension_model, grading)
    K = model.stiffness_dense()
    M = model.M.toarray()
    C = np.zeros_like(K)
    for d in dampers:
        node = int(np.argmin(np.abs(model.node_x - d.position)))
        dof = model.disp_index[node]
        C[dof, dof] += d.coefficient
    n = K.shape[0]
    if not 1 <= n_modes < n:
        raise ValueError(f"n_modes must be 1 … {n - 1}, got {n_modes}")
    identity = np.eye(n)
    A = np.block([[np.zeros((n, n)), identity], [-K, -C]])
    B = np.block([[identity, np.zeros((n, n))], [np.zeros((n, n)), M]])
    s = sla.eigvals(A, B)
    s = s[np.isfinite(s) & (s.imag > 0)]
    s = s[np.argsort(np.abs(s))]
    if s.size < n_modes:
        raise ComputationError(f"the quadratic eigenproblem gave {s.size} oscillating modes, {n_modes} asked")
    s = s[:n_modes]
    return ComplexModes(s=s, frequency=np.abs(s) / (2 * np.pi), damping=-s.real / np.abs(s))
