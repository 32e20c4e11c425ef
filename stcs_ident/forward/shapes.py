"""Mode shapes from the exact dynamic stiffness.

At a natural frequency ω_k the global matrix K(ω_k) is singular; its null
vector gives the nodal displacements, rotations and the additional tension
ĥ, and Eq. (3) of ``docs/model.md`` gives φ(x) on every segment. Shapes are
mass-normalised, ∫ m φ² dx + Σ M_k φ(x_k)² = 1, the integral by composite
Gauss–Legendre on sub-intervals that resolve both the wavelength and the
boundary layers of width 1/p at the segment ends.
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
from .dsm import natural_frequencies

_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


@dataclass(frozen=True)
class ModeShapes:
    """Mass-normalised mode shapes of one configuration.

    Attributes
    ----------
    frequencies : ndarray (n_modes,)
        Natural frequencies, Hz.
    additional_tension : ndarray (n_modes,) or (n_modes, n_segments)
        ĥ per unit modal amplitude (N), one per segment for "per-segment".
    nodes : ndarray (n_attachments + 2,)
        Node positions: 0, the attachments, l.
    """

    frequencies: np.ndarray
    additional_tension: np.ndarray
    nodes: np.ndarray
    _segments: list
    _homogeneous: list  # per mode: per segment coefficient tuples
    _particular: np.ndarray  # (n_modes, n_segments): constant w ĥ /(H m ω²)

    def __call__(self, x) -> np.ndarray:
        """φ_k(x) for positions ``x`` (m), shape (len(x), n_modes)."""
        x = np.atleast_1d(np.asarray(x, float))
        if np.any((x < 0) | (x > self.nodes[-1])):
            raise ValueError("positions must lie within the span [0, l]")
        seg = np.clip(np.searchsorted(self.nodes, x, side="right") - 1, 0, len(self.nodes) - 2)
        out = np.empty((x.size, len(self.frequencies)))
        for j in range(len(self.nodes) - 1):
            sel = seg == j
            if not sel.any():
                continue
            z = x[sel] - 0.5 * (self.nodes[j] + self.nodes[j + 1])
            for k in range(len(self.frequencies)):
                out[sel, k] = self._segments[k][j].evaluate(self._homogeneous[k][j], z) + self._particular[k, j]
        return out

    def quadrature(self):
        """Points and weights of the composite rule used for normalisation."""
        pts, wts = [], []
        for j in range(len(self.nodes) - 1):
            a, b = self.nodes[j], self.nodes[j + 1]
            seg = self._segments[-1][j]  # highest mode: finest wavelength
            L = b - a
            n_wave = math.ceil(2 * float(seg.q) * L / math.pi) + 2
            breaks = set(np.linspace(0.0, L, n_wave + 1).tolist())
            p = float(getattr(seg, "p", 0.0))
            if p * L > 4:
                for i in range(-3, 6):
                    d = 2.0**i / p
                    if d < L / 2:
                        breaks.update((d, L - d))
            br = np.array(sorted(breaks))
            lo, hi = br[:-1, None], br[1:, None]
            pts.append((a + lo + 0.5 * (hi - lo) * (_GL_X + 1)).ravel())
            wts.append((0.5 * (hi - lo) * _GL_W).ravel())
        return np.concatenate(pts), np.concatenate(wts)


def mode_shapes(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int = 6, *,
                tension_model: str = "uniform", plane: str = "in") -> ModeShapes:
    """Natural frequencies and mass-normalised mode shapes of one configuration.

    A mode whose nodes are all at rest (a bare clamped cable without
    sag-extensibility has no nodal unknowns at all; a string with a mass at
    midspan has its antisymmetric modes so) is invisible to the nodal
    values. Such a configuration is solved again with a null attachment
    (no mass, no spring: it changes no frequency or shape) at an irrational
    fraction of the span, where no such node falls.

    ``plane``: ``"in"`` or ``"out"`` (:func:`~stcs_ident.core.planes.plane_view`).
    """
    cable, attachments = plane_view(cable, attachments, plane)
    try:
        return _mode_shapes(cable, attachments, tension, n_modes, tension_model)
    except _NodesAtRest:
        node = _null_node(cable.length, attachments)
        try:
            return _mode_shapes(cable, (*attachments, node), tension, n_modes, tension_model)
        except _NodesAtRest:  # a bare string: one null node is one unknown, too few to tell a null vector
            second = _null_node(cable.length, (*attachments, node))
            return _mode_shapes(cable, (*attachments, node, second), tension, n_modes, tension_model)


class _NodesAtRest(ComputationError):
    pass


def _null_node(length: float, attachments: Sequence[Attachment]) -> Attachment:
    """A null attachment at an irrational fraction of the span, the candidate
    farthest from the existing attachments."""
    candidates = length * np.array([0.381966011250105, 0.618033988749895, 0.292893218813452,
                                    0.707106781186548, 0.414213562373095, 0.585786437626905])
    taken = np.array([a.position for a in attachments])
    if taken.size:
        gaps = np.min(np.abs(candidates[:, None] - taken[None, :]), axis=1)
        return Attachment("(null node)", float(candidates[np.argmax(gaps)]))
    return Attachment("(null node)", float(candidates[0]))


def _mode_shapes(cable, attachments, tension, n_modes, tension_model) -> ModeShapes:
    atts = sorted(attachments, key=lambda a: a.position)
    freqs = natural_frequencies(cable, atts, tension, n_modes, tension_model=tension_model, plane=None)
    _, [(batch, _)] = build_batch(cable, atts, float(tension), tension_model=tension_model)
    topo = batch.topology
    nodes = np.concatenate([[0.0], [a.position for a in atts], [cable.length]])
    idx = np.zeros(1, dtype=np.int64)
    segments, coefficients, particular, h_all = [], [], [], []
    for f in freqs:
        omega = np.array([2 * math.pi * f])
        seg = batch.segments(idx, omega)
        K, _ = batch.assemble(idx, omega, segments=seg)
        s = batch._scale[0]
        if batch.n_dof == 0:
            raise _NodesAtRest("no nodal unknowns")
        lam, vec = np.linalg.eigh(K[0] * s[:, None] * s[None, :])
        order = np.argsort(np.abs(lam))
        if len(lam) == 1 or abs(lam[order[0]]) > 1e-6 * abs(lam[order[1]]):
            # K(ω_k) is regular: the mode lives inside segments whose clamped
            # frequency equals ω_k (nodes at rest), beyond nodal values
            raise _NodesAtRest(
                f"mode at {f:.6g} Hz coincides with a clamped-segment frequency; "
                "its shape is not defined by the nodal values"
            )
        z = s * vec[:, order[0]]
        h = z[batch.h_dof] if topo.n_h else np.zeros(0)
        objs, per_seg, part = segment_solutions(batch, seg, z, omega[0])
        segments.append(objs)
        coefficients.append(per_seg)
        particular.append(part)
        h_all.append(h)
    shapes = ModeShapes(np.asarray(freqs), np.array(h_all), nodes, segments, coefficients, np.array(particular))
    return _normalised(shapes, cable, atts)


def segment_solutions(batch, seg, z: np.ndarray, omega) -> tuple[list, list, np.ndarray]:
    """Each segment's exact solution for the nodal unknowns ``z`` (null vector of K at ``omega``, real or
    complex): the segments as scalars, their homogeneous coefficients and the particular part γ ĥ."""
    topo = batch.topology
    dof = np.append(z, 0.0).__getitem__  # index −1 (a fixed dof) reads 0
    h = z[batch.h_dof] if topo.n_h else np.zeros(0)
    gamma = batch.w[0] / (batch.H[0] * batch.m[0] * omega**2)
    part = np.zeros(topo.n_segments, dtype=np.result_type(z, omega))
    objs, per_seg = [], []
    for j in range(topo.n_segments):
        hj = 0.0 if topo.n_h == 0 else (h[0] if topo.tension_model == "uniform" else h[j])
        part[j] = gamma * hj
        one = _segment_slice(seg, j)
        objs.append(one)
        v1, v2 = dof(batch.v_dof[j]) - part[j], dof(batch.v_dof[j + 1]) - part[j]
        if topo.string:
            per_seg.append(one.shape_coefficients(v1, v2))
        else:
            per_seg.append(one.shape_coefficients(v1, dof(batch.t_dof[j]), v2, dof(batch.t_dof[j + 1])))
    return objs, per_seg, part


def _segment_slice(seg, j):
    """A view of segment j of a (1, n_segments) segment batch as scalars."""
    def pick(v):
        if isinstance(v, np.ndarray) and v.ndim == 2:
            return v[0, j if v.shape[1] > 1 else 0]
        if isinstance(v, np.ndarray) and v.ndim == 1:
            return v[0]
        return v

    one = object.__new__(type(seg))
    for name, value in vars(seg).items():
        setattr(one, name, tuple(pick(v) for v in value) if isinstance(value, tuple) else pick(value))
    return one


def modal_masses(shapes: ModeShapes, cable: Cable, attachments: Sequence[Attachment]) -> np.ndarray:
    """Mass matrix of the shapes: ∫ m φ_i φ_j dx + Σ M_k φ_i(x_k) φ_j(x_k)."""
    x, w = shapes.quadrature()
    phi = shapes(x)
    M = cable.mass_per_length * (phi * w[:, None]).T @ phi
    for a in attachments:
        pa = shapes(np.array([a.position]))[0]
        M += a.mass * np.outer(pa, pa)
    return M


def _normalised(shapes: ModeShapes, cable, atts) -> ModeShapes:
    mass = np.diag(modal_masses(shapes, cable, atts))
    x = np.linspace(0, cable.length, 201)
    phi = shapes(x)
    sign = np.sign(phi[np.argmax(np.abs(phi), axis=0), np.arange(phi.shape[1])])
    factor = sign / np.sqrt(mass)
    coefficients = [
        [tuple(c * factor[k] for c in seg) for seg in mode] for k, mode in enumerate(shapes._homogeneous)
    ]
    h = shapes.additional_tension * (factor[:, None] if shapes.additional_tension.ndim == 2 else factor)
    return ModeShapes(shapes.frequencies, h, shapes.nodes, shapes._segments, coefficients,
                      shapes._particular * factor[:, None])
