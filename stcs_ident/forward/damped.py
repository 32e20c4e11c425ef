"""Complex modes of a cable with dampers, exact: the dynamic stiffness at a complex eigenvalue s.

Prototype (issue 13): segments between attachments and dampers are the exact tensioned-beam (or string)
elements of :mod:`.elements` evaluated at ω = −i s (m ω² = −m s²); an attachment adds m s² + k at its node,
a damper k_d + c s + m_d s². Without the sag term (``EA`` ignored). Each mode is followed from its
undamped root (the certified Wittrick–Williams solve, dampers replaced by their springs and masses) as the
dashpots grow from 0 to their values, by Newton steps on log det K(s).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..errors import ComputationError
from ..model import Attachment, Cable, Damper
from .dsm import natural_frequencies
from .elements import BeamSegment, StringSegment
from .fem_damped import ComplexModes

__all__ = ["complex_modes"]


def _stiffness(cable: Cable, tension: float, points: np.ndarray, point_terms, s: complex) -> np.ndarray:
    """K(s) on the free degrees of freedom: nodes at the ends and at ``points``; ``point_terms`` (k, c, m)."""
    x = np.concatenate(([0.0], points, [cable.length]))
    lengths = np.diff(x)
    omega = -1j * s
    beam = cable.EI > 0
    per = 2 if beam else 1
    n = per * x.size
    K = np.zeros((n, n), dtype=complex)
    if beam:
        seg = BeamSegment(lengths, cable.EI, tension, cable.mass_per_length, np.full(lengths.size, omega))
    else:
        seg = StringSegment(lengths, tension, cable.mass_per_length, np.full(lengths.size, omega))
    blocks = seg.matrix()
    for j in range(lengths.size):
        dofs = slice(per * j, per * j + 2 * per)
        K[dofs, dofs] += blocks[j]
    for i, (k, c, m) in enumerate(point_terms, start=1):
        K[per * i, per * i] += k + c * s + m * s * s
    free = np.ones(n, dtype=bool)
    free[0] = free[per * (x.size - 1)] = False  # no displacement at the anchorages
    if beam:
        for dof, boundary in ((1, cable.boundary_a), (n - 1, cable.boundary_b)):
            if boundary.is_clamped:
                free[dof] = False
            else:
                K[dof, dof] += boundary.rotational_stiffness
    return K[np.ix_(free, free)]


def _points(attachments, dampers, scale: float):
    """Node positions and (k, c, m) per node, attachments and dampers at one position merged."""
    terms: dict[float, list[float]] = {}
    for a in attachments:
        terms.setdefault(a.position, [0.0, 0.0, 0.0])
        terms[a.position][0] += a.stiffness
        terms[a.position][2] += a.mass
    for d in dampers:
        terms.setdefault(d.position, [0.0, 0.0, 0.0])
        terms[d.position][0] += d.stiffness
        terms[d.position][1] += scale * d.coefficient
        terms[d.position][2] += d.mass
    points = np.array(sorted(terms))
    return points, [tuple(terms[p]) for p in points]


def _newton(cable, tension, points, terms, s: complex, tol: float = 1e-12, max_iter: int = 50) -> complex:
    for _ in range(max_iter):
        h = 1e-7 * abs(s)
        K = _stiffness(cable, tension, points, terms, s)
        dK = (_stiffness(cable, tension, points, terms, s + h) - _stiffness(cable, tension, points, terms, s - h))
        dK /= 2 * h
        try:
            step = 1.0 / np.trace(np.linalg.solve(K, dK))  # 1 / (d/ds log det K)
        except np.linalg.LinAlgError:  # exactly on a root or a pole of a segment: step off it
            s *= 1 + 1e-9j
            continue
        s -= step
        if abs(step) < tol * abs(s):
            return s
    raise ComputationError(f"a damped mode near {abs(s) / (2 * np.pi):.6g} Hz did not converge")


def complex_modes(cable: Cable, attachments: Sequence[Attachment], dampers: Sequence[Damper], tension: float,
                  n_modes: int, steps: int = 16) -> ComplexModes:
    """The first ``n_modes`` complex modes (see the module docstring); the sag term is left out."""
    cable = replace(cable, EA=None)
    undamped = list(attachments) + [Attachment(f"damper {d.name}", d.position, d.mass, d.stiffness) for d in dampers]
    f0 = natural_frequencies(cable, undamped, tension, n_modes, tension_model="none")
    roots = []
    for f in np.asarray(f0).ravel():
        s = 2j * np.pi * f
        for k in range(1, steps + 1):  # the dashpots from 0 to their values
            points, terms = _points(attachments, dampers, (k / steps) ** 2)
            s = _newton(cable, tension, points, terms, s)
        roots.append(s)
    s = np.array(roots)
    if np.unique(np.round(s / abs(s).max(), 9)).size < s.size:
        raise ComputationError("two damped modes' paths merged: the continuation lost a mode")
    order = np.argsort(np.abs(s))
    s = s[order]
    return ComplexModes(s=s, frequency=np.abs(s) / (2 * np.pi), damping=-s.real / np.abs(s))
