"""Global dynamic stiffness and the Wittrick–Williams count, for a batch.

A :class:`CableBatch` holds many configurations of one topology (same
number of attachments, same kind of end at A and at B, same tension model):
arrays of lengths, tensions, bending stiffnesses, attachment positions,
masses and springs, end stiffnesses. :meth:`CableBatch.evaluate` builds the
symmetric matrix K(ω) on the nodal displacements and rotations plus the
additional tension ĥ (one global unknown, or one per segment for the
paper's form), factorises it without row interchanges and returns the count

    J(ω) = J0(ω) + s{K(ω)} − n_h

of natural frequencies below ω, with det K(ω) for root refinement.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..core.errors import ComputationError
from .elements import BeamSegment, StringSegment
from .statics import end_slopes, stretched_lengths


@dataclass(frozen=True)
class Topology:
    """What is shared by every configuration of a batch."""

    n_attachments: int
    clamped_a: bool
    clamped_b: bool
    string: bool  # EI = 0
    tension_model: str  # "uniform" | "per-segment" | "none" (after EA is considered)

    @property
    def n_segments(self) -> int:
        return self.n_attachments + 1

    @property
    def n_h(self) -> int:
        return {"uniform": 1, "per-segment": self.n_segments, "none": 0}[self.tension_model]

    def dof_map(self):
        """Global indices of (v, θ) per node (−1 where fixed) and of the ĥ unknowns."""
        n_nodes = self.n_attachments + 2
        v = np.full(n_nodes, -1)
        t = np.full(n_nodes, -1)
        k = 0
        for i in range(n_nodes):
            end = i in (0, n_nodes - 1)
            if not end:
                v[i] = k
                k += 1
            if not self.string:
                free_rotation = (i == 0 and not self.clamped_a) or (i == n_nodes - 1 and not self.clamped_b)
                if not end or free_rotation:
                    t[i] = k
                    k += 1
        h = np.arange(k, k + self.n_h)
        return v, t, h, k + self.n_h


class CableBatch:
    """Many cable configurations of one :class:`Topology`.

    Parameters (arrays of shape (n,), attachment arrays (n, n_attachments))
    ----------
    length, mass_per_length, EI, tension : chord length, m, EI, H
    EA : axial stiffness (ignored when the tension model is "none")
    weight : w = m g cos θ, N/m
    gcos : g cos θ, m/s²
    positions, masses, springs : attachments, ascending positions
    end_a, end_b : rotational stiffness at A and B (inf = clamped)
    dashpots : the attachments' viscous coefficients (N s/m; a damper's), or None; used only by the
        complex solver (:mod:`.damped`), never by :meth:`assemble`
    """

    def __init__(self, topology, *, length, mass_per_length, EI, tension, EA, weight, gcos,
                 positions, masses, springs, end_a, end_b, dashpots=None):
        self.topology = topology
        self.length = length
        self.m = mass_per_length
        self.EI = EI
        self.H = tension
        self.EA = EA
        self.w = weight
        self.positions = positions
        self.masses = masses
        self.springs = springs
        self.end_a = end_a
        self.end_b = end_b
        self.dashpots = np.zeros_like(masses) if dashpots is None else dashpots
        self.kinks = masses * gcos[:, None] / tension[:, None]
        self.seg_len, self.slope_start, self.slope_end = end_slopes(
            length, positions, weight / tension, self.kinks
        )
        self.stretched = stretched_lengths(self.seg_len, self.slope_start, self.slope_end)
        self._stretched_total = self.stretched.sum(axis=1)
        self.v_dof, self.t_dof, self.h_dof, self.n_dof = _dof_map(topology)
        self._constant = self._constant_part()
        self._scale = self._dof_scales()

    def __len__(self):
        return len(self.length)

    def segments(self, idx, omega):
        """Segment quantities for configurations ``idx`` at ``omega``, shape (len(idx), n_segments)."""
        L = self.seg_len[idx]
        if self.topology.string:
            return StringSegment(L, self.H[idx, None], self.m[idx, None], omega[:, None])
        return BeamSegment(L, self.EI[idx, None], self.H[idx, None], self.m[idx, None], omega[:, None])

    def element_dofs(self, j):
        return _element_dofs(self.topology, j)

    @property
    def _scatter(self):
        return _scatter_matrix(self.topology)

    def _constant_part(self):
        """The ω-independent part of K per configuration: springs, end
        restraints, the −L_e/EA diagonal and the static-slope couplings.

        Every entry receives one term at most, so all are written by one
        indexed addition onto zeros (positions from :func:`_constant_layout`)."""
        topo = self.topology
        n = len(self.length)
        values = []
        if topo.n_attachments:
            values.append(self.springs)
        if not topo.string:
            for node, end in ((0, self.end_a), (topo.n_attachments + 1, self.end_b)):
                if self.t_dof[node] >= 0:
                    values.append(end[:, None])
        if topo.tension_model == "uniform":
            values.append(-(self._stretched_total / self.EA)[:, None])
            if topo.n_attachments:
                values += [self.kinks, self.kinks]
        elif topo.tension_model == "per-segment":
            for j in range(topo.n_segments):
                values.append(-(self.stretched[:, j] / self.EA)[:, None])
                for node, slope in ((j, -self.slope_start[:, j]), (j + 1, self.slope_end[:, j])):
                    if self.v_dof[node] >= 0:
                        values += [slope[:, None], slope[:, None]]
        K = np.zeros((n, self.n_dof * self.n_dof))
        if values:
            K[:, _constant_layout(topo)] += np.concatenate(values, axis=1)
        return K

    def _dof_scales(self):
        """Fixed (ω-independent) scale of every unknown, so that the scaled
        matrix s_i K_ij s_j has entries of order one: displacement rows are
        of order H p, rotation rows EI p (p ≈ √(H/EI), at least 1/l), the ĥ
        rows L_e/EA. A congruence keeps the inertia, and a fixed scaling
        only multiplies det K by a positive constant."""
        topo = self.topology
        n = len(self.length)
        if topo.string:
            p = 1.0 / self.length
        elif self.EI.all():  # the usual case: no division by zero to silence
            p = np.maximum(np.sqrt(self.H / self.EI), 1.0 / self.length)
        else:
            with np.errstate(divide="ignore"):
                p = np.maximum(np.sqrt(self.H / self.EI), 1.0 / self.length)
        scale = np.ones((n, self.n_dof))
        v, t = _free_dofs(topo)
        scale[:, v] = 1.0 / np.sqrt(self.H * p)[:, None]
        if t.size:
            scale[:, t] = 1.0 / np.sqrt(self.EI * p)[:, None]
        if topo.n_h:
            scale[:, self.h_dof] = np.sqrt(self.EA / self._stretched_total)[:, None]
        return scale

    def assemble(self, idx, omega, segments=None):
        """K(ω) of shape (len(idx), n_dof, n_dof), and the J0 count (None for a complex ω)."""
        topo = self.topology
        n = len(idx)
        seg = self.segments(idx, omega) if segments is None else segments
        J0 = None if np.iscomplexobj(omega) else seg.clamped_count().sum(axis=1)  # complex ω: the damped modes
        parts = [seg.matrix().reshape(n, -1)]
        if topo.tension_model != "none":
            gamma = self.w[idx] / (self.H[idx] * self.m[idx] * omega * omega)
            parts.append((-gamma[:, None, None] * seg.translation_force()).reshape(n, -1))
            parts.append(gamma[:, None] ** 2 * seg.translation_residual)
        if topo.n_attachments:
            parts.append(-self.masses[idx] * (omega * omega)[:, None])
        V = np.concatenate(parts, axis=1)
        K = self._constant[idx] + V @ self._scatter
        return K.reshape(n, self.n_dof, self.n_dof), J0

    def evaluate(self, idx, omega):
        """Wittrick–Williams count J(ω), det K(ω) and J0(ω) for configurations ``idx``."""
        K, J0 = self.assemble(idx, omega)
        s = self._scale[idx]
        negative, det = negative_pivots(K * s[:, :, None] * s[:, None, :])
        return J0 + negative - self.topology.n_h, det, J0


@functools.lru_cache(maxsize=64)
def _dof_map(topology):
    return topology.dof_map()


@functools.lru_cache(maxsize=64)
def _scatter_matrix(topo):
    """0/1 matrix S such that vec K = vec K_const + V S, where V holds, per
    item, the frequency-dependent values in the order of :meth:`assemble`:
    element matrices, ĥ couplings, ĥ diagonals, −M ω² of the attachments."""
    nd = _dof_map(topo)[3]
    h_dof = _dof_map(topo)[2]
    ne = 2 if topo.string else 4
    targets = []  # one list of (row, col) per column of V
    for j in range(topo.n_segments):
        dofs = _element_dofs(topo, j)
        for r in range(ne):
            for c in range(ne):
                ok = dofs[r] >= 0 and dofs[c] >= 0
                targets.append([(dofs[r], dofs[c])] if ok else [])
    if topo.tension_model != "none":
        for j in range(topo.n_segments):
            h = h_dof[0] if topo.tension_model == "uniform" else h_dof[j]
            for r, d in enumerate(_element_dofs(topo, j)):
                targets.append([(d, h), (h, d)] if d >= 0 else [])
        for j in range(topo.n_segments):
            h = h_dof[0] if topo.tension_model == "uniform" else h_dof[j]
            targets.append([(h, h)])
    for k in range(topo.n_attachments):
        v = _dof_map(topo)[0][k + 1]
        targets.append([(v, v)])
    S = np.zeros((len(targets), nd * nd))
    for col, pairs in enumerate(targets):
        for r, c in pairs:
            S[col, r * nd + c] += 1.0
    return S


@functools.lru_cache(maxsize=64)
def _constant_layout(topo):
    """Flat positions (row × n_dof + column) in K of the terms of
    :meth:`CableBatch._constant_part`, in the order it lists them."""
    v, t, h, nd = _dof_map(topo)
    pairs = [(v[k + 1], v[k + 1]) for k in range(topo.n_attachments)]
    if not topo.string:
        pairs += [(t[node], t[node]) for node in (0, topo.n_attachments + 1) if t[node] >= 0]
    if topo.tension_model == "uniform":
        pairs.append((h[0], h[0]))
        inner = v[1:-1]
        pairs += [(d, h[0]) for d in inner] + [(h[0], d) for d in inner]
    elif topo.tension_model == "per-segment":
        for j in range(topo.n_segments):
            pairs.append((h[j], h[j]))
            for node in (j, j + 1):
                if v[node] >= 0:
                    pairs += [(v[node], h[j]), (h[j], v[node])]
    flat = np.array([r * nd + c for r, c in pairs], dtype=np.intp)
    assert len(set(flat.tolist())) == len(flat), "one term per entry"
    flat.flags.writeable = False
    return flat


@functools.lru_cache(maxsize=64)
def _free_dofs(topo):
    """Indices of the free displacement and rotation unknowns."""
    v, t, _, _ = _dof_map(topo)
    return v[v >= 0], t[t >= 0]


def _element_dofs(topo, j):
    v, t, _, _ = _dof_map(topo)
    if topo.string:
        return np.array([v[j], v[j + 1]])
    return np.array([v[j], t[j], v[j + 1], t[j + 1]])


#: Below this many matrices one batched LAPACK call is faster than
#: elimination vectorised across the batch.
SMALL_BATCH = 256


def negative_pivots(K):
    """Number of negative eigenvalues and determinant of symmetric matrices.

    Small batches use LAPACK's symmetric eigenvalues; large ones Gaussian
    elimination without row interchanges, vectorised across the batch (by
    Sylvester's law of inertia the negative pivots count the negative
    eigenvalues). An exactly zero pivot (a matrix evaluated exactly at a
    root) is replaced by a relative 1e-14, which keeps the count and
    leaves the determinant at round-off size.

    Raises
    ------
    ComputationError
        If a matrix is not finite (LAPACK would fail on it, and elimination
        would count nonsense).
    """
    if not np.all(np.isfinite(K)):
        raise ComputationError("the dynamic stiffness matrix is not finite (attachments nearly coincident, or an "
                               "extreme parameter value)")
    if K.shape[-1] == 0:  # no free unknown (a pinned string without attachments): no pivot, det 1
        return np.zeros(K.shape[0], dtype=np.int64), np.ones(K.shape[0])
    if K.shape[0] <= SMALL_BATCH:
        lam = np.linalg.eigvalsh(K)
        with np.errstate(over="ignore"):  # a determinant beyond 1e308 is inf: the root search then bisects
            return np.count_nonzero(lam < 0, axis=-1), np.prod(lam, axis=-1)
    A = K.copy()
    n = A.shape[-1]
    negative = np.zeros(A.shape[0], dtype=np.int64)
    det = np.ones(A.shape[0])
    floor = 1e-14 * np.abs(K).max(axis=(1, 2))
    for k in range(n):
        d = A[:, k, k]
        d = np.where(d == 0, floor, d)
        negative += d < 0
        with np.errstate(over="ignore"):  # as above
            det *= d
        if k + 1 < n:
            l = A[:, k + 1:, k] / d[:, None]
            A[:, k + 1:, k + 1:] -= l[:, :, None] * A[:, None, k, k + 1:]
    return negative, det
