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

from dataclasses import dataclass

import numpy as np

from .elements import BeamSegment, StringSegment
from .statics import end_slopes, stretched_lengths

TENSION_MODELS = ("uniform", "per-segment", "none")


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
    """

    def __init__(self, topology, *, length, mass_per_length, EI, tension, EA, weight, gcos,
                 positions, masses, springs, end_a, end_b):
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
        self.kinks = masses * gcos[:, None] / tension[:, None]
        self.seg_len, self.slope_start, self.slope_end = end_slopes(
            length, positions, weight / tension, self.kinks
        )
        self.stretched = stretched_lengths(self.seg_len, self.slope_start, self.slope_end)
        self.v_dof, self.t_dof, self.h_dof, self.n_dof = topology.dof_map()

    def __len__(self):
        return len(self.length)

    def segments(self, idx, omega):
        """Segment quantities for configurations ``idx`` at ``omega``, shape (len(idx), n_segments)."""
        L = self.seg_len[idx]
        col = (lambda a: a[idx, None])
        if self.topology.string:
            return StringSegment(L, col(self.H), col(self.m), omega[:, None])
        return BeamSegment(L, col(self.EI), col(self.H), col(self.m), omega[:, None])

    def element_dofs(self, j):
        if self.topology.string:
            return np.array([self.v_dof[j], self.v_dof[j + 1]])
        return np.array([self.v_dof[j], self.t_dof[j], self.v_dof[j + 1], self.t_dof[j + 1]])

    def assemble(self, idx, omega, segments=None):
        """K(ω) of shape (len(idx), n_dof, n_dof), and the J0 count."""
        topo = self.topology
        n = len(idx)
        K = np.zeros((n, self.n_dof, self.n_dof))
        seg = self.segments(idx, omega) if segments is None else segments
        J0 = seg.clamped_count().sum(axis=1)
        Ke = seg.matrix()
        with_h = topo.tension_model != "none"
        if with_h:
            H = self.H[idx]
            gamma = self.w[idx] / (H * self.m[idx] * omega * omega)
            force = -gamma[:, None, None] * seg.translation_force()
            residual = gamma[:, None] ** 2 * seg.translation_residual
        for j in range(topo.n_segments):
            dofs = self.element_dofs(j)
            keep = np.flatnonzero(dofs >= 0)
            d = dofs[keep]
            K[:, d[:, None], d[None, :]] += Ke[:, j, keep[:, None], keep[None, :]]
            if not with_h:
                continue
            h = self.h_dof[0] if topo.tension_model == "uniform" else self.h_dof[j]
            K[:, d, h] += force[:, j, keep]
            K[:, h, d] += force[:, j, keep]
            K[:, h, h] += residual[:, j]
            if topo.tension_model == "per-segment":
                K[:, h, h] -= self.stretched[idx, j] / self.EA[idx]
                for node, slope in ((j, -self.slope_start[idx, j]), (j + 1, self.slope_end[idx, j])):
                    v = self.v_dof[node]
                    if v >= 0:
                        K[:, v, h] += slope
                        K[:, h, v] += slope
        if topo.tension_model == "uniform":
            h = self.h_dof[0]
            K[:, h, h] -= self.stretched[idx].sum(axis=1) / self.EA[idx]
        if topo.n_attachments:
            v = self.v_dof[1:-1]
            K[:, v, v] += self.springs[idx] - self.masses[idx] * (omega * omega)[:, None]
            if topo.tension_model == "uniform":
                K[:, v, self.h_dof[0]] += self.kinks[idx]
                K[:, self.h_dof[0], v] += self.kinks[idx]
        if not topo.string:
            for node, end in ((0, self.end_a), (topo.n_attachments + 1, self.end_b)):
                t = self.t_dof[node]
                if t >= 0:
                    K[:, t, t] += end[idx]
        return K, J0

    def evaluate(self, idx, omega):
        """Wittrick–Williams count J(ω), det K(ω) and J0(ω) for configurations ``idx``."""
        K, J0 = self.assemble(idx, omega)
        negative, det = negative_pivots(K)
        return J0 + negative - self.topology.n_h, det, J0


def negative_pivots(K):
    """Negative pivots and determinant of symmetric matrices, by elimination
    without row interchanges (Sylvester's law of inertia: the count equals
    the number of negative eigenvalues)."""
    A = K.copy()
    n = A.shape[-1]
    negative = np.zeros(A.shape[0], dtype=np.int64)
    det = np.ones(A.shape[0])
    for k in range(n):
        d = A[:, k, k]
        negative += d < 0
        det *= d
        if k + 1 < n:
            l = A[:, k + 1:, k] / d[:, None]
            A[:, k + 1:, k + 1:] -= l[:, :, None] * A[:, None, k, k + 1:]
    return negative, det
