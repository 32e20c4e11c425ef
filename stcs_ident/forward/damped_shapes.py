"""Complex mode shapes of a cable with dampers, from the exact dynamic stiffness.

At an eigenvalue s the matrix K(s) of :mod:`.damped` is singular; its null vector gives the nodal
displacements, rotations and the additional tension, and each segment's exact solution at ω = −i s gives
φ(x) between the nodes (the same formulas as :mod:`.shapes`, with complex wavenumbers). A damper makes the
shape complex: its phase varies along the span (a travelling-wave part that carries energy into the
dashpot), where an undamped shape is a standing wave of one phase. Shapes are scaled to a peak modulus
of 1, real and positive there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core.errors import ComputationError
from ..core.model import Attachment, Cable
from ..core.planes import plane_view
from .batch import build_batch
from .damped import batch_complex_modes
from .shapes import segment_solutions

__all__ = ["ComplexShapes", "complex_mode_shapes"]


@dataclass(frozen=True)
class ComplexShapes:
    """Complex mode shapes of one configuration.

    Attributes
    ----------
    s : ndarray (n_modes,)
        Eigenvalues, rad/s.
    nodes : ndarray
        0, the attachments' and dampers' positions, l.
    """

    s: np.ndarray
    nodes: np.ndarray
    _segments: list
    _coefficients: list
    _particular: np.ndarray
    _scale: np.ndarray

    @property
    def frequency(self) -> np.ndarray:
        """|s|/2π, Hz."""
        return np.abs(self.s) / (2 * math.pi)

    @property
    def damping(self) -> np.ndarray:
        """−Re(s)/|s|."""
        return -self.s.real / np.abs(self.s)

    def __call__(self, x) -> np.ndarray:
        """φ_k(x) (complex) at positions ``x`` (m), shape (len(x), n_modes)."""
        x = np.atleast_1d(np.asarray(x, float))
        if np.any((x < 0) | (x > self.nodes[-1])):
            raise ValueError("positions must lie within the span [0, l]")
        seg = np.clip(np.searchsorted(self.nodes, x, side="right") - 1, 0, len(self.nodes) - 2)
        out = np.empty((x.size, self.s.size), dtype=complex)
        for j in range(len(self.nodes) - 1):
            sel = seg == j
            if not sel.any():
                continue
            z = x[sel] - 0.5 * (self.nodes[j] + self.nodes[j + 1])
            for k in range(self.s.size):
                out[sel, k] = (self._segments[k][j].evaluate(self._coefficients[k][j], z)
                               + self._particular[k, j]) * self._scale[k]
        return out


def complex_mode_shapes(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int = 6, *,
                        tension_model: str = "uniform", plane: str = "in") -> ComplexShapes:
    """The first ``n_modes`` complex modes of a configuration with dampers (see the module docstring).

    Raises
    ------
    ComputationError
        If K(s) is not singular at an eigenvalue (a mode whose nodes all rest).
    """
    cable, attachments = plane_view(cable, attachments, plane)
    atts = sorted(attachments, key=lambda a: a.position)
    roots = batch_complex_modes(cable, atts, float(tension), n_modes, tension_model=tension_model, plane=None)
    _, [(batch, _)] = build_batch(cable, atts, float(tension), tension_model=tension_model)
    nodes = np.concatenate([[0.0], [a.position for a in atts], [cable.length]])
    idx = np.zeros(1, dtype=np.int64)
    segments, coefficients, particular = [], [], []
    for s in roots:
        omega = np.array([-1j * s])
        seg = batch.segments(idx, omega)
        K, _ = batch.assemble(idx, omega, segments=seg)
        v = batch.v_dof[1:-1]
        K[0, v, v] += batch.dashpots[0] * s
        scale = batch._scale[0]
        _, sv, vh = np.linalg.svd(K[0] * scale[:, None] * scale[None, :])
        if sv.size > 1 and sv[-1] > 1e-6 * sv[-2]:
            raise ComputationError(f"the damped mode at {abs(s) / (2 * math.pi):.6g} Hz is not a null vector of "
                                   "the nodal unknowns (its nodes all rest)")
        z = scale * vh[-1].conj()
        objs, per_seg, part = segment_solutions(batch, seg, z, omega[0])
        segments.append(objs)
        coefficients.append(per_seg)
        particular.append(part)
    shapes = ComplexShapes(roots, nodes, segments, coefficients, np.array(particular), np.ones(roots.size, complex))
    x = np.linspace(0.0, cable.length, 801)
    phi = shapes(x)
    peak = phi[np.argmax(np.abs(phi), axis=0), np.arange(roots.size)]
    return ComplexShapes(roots, nodes, segments, coefficients, np.array(particular), 1.0 / peak)
