"""Exact dynamic stiffness of one cable segment (vectorised, stable form).

A segment of length L with tension H, bending stiffness EI and mass per
length m vibrating at ω has the homogeneous solution

    φ(z) = A cosh(pz) + B cos(qz) + C sinh(pz) + D sin(qz),   z = x − L/2,

p² = H/(2EI) + √((H/2EI)² + mω²/EI), q² = p² − H/EI. The symmetric part
(A, B) and the antisymmetric part (C, D) decouple. Every hyperbolic
function appears only as tanh(pL/2) or as cosh(pz)/cosh(pL/2), so nothing
overflows or cancels when pL reaches the hundreds (a taut strand).

Nodal degrees of freedom are (v1, θ1, v2, θ2) = (φ, φ') at x = 0 and x = L;
the element matrix K satisfies dᵀ K d = ∫(EI φ''² + H φ'² − mω² φ²) dx for
the exact solution with end values d.
"""

from __future__ import annotations

import numpy as np


def _real_or_complex(x):
    """``x`` as a float array, or complex if it is (a complex frequency: the damped modes)."""
    x = np.asarray(x)
    return x if np.iscomplexobj(x) else x.astype(float)


def _x_cos_minus_sin(x):
    """x cos x − sin x without cancellation near 0."""
    x = _real_or_complex(x)
    x2 = x * x
    series = x * x2 * (-1.0 / 3 + x2 * (1.0 / 30 + x2 * (-1.0 / 840 + x2 / 45360)))
    return np.where(np.abs(x) < 0.1, series, x * np.cos(x) - np.sin(x))


def _x_minus_tanh(x):
    """x − tanh x without cancellation near 0."""
    x = _real_or_complex(x)
    x2 = x * x
    series = x * x2 * (1.0 / 3 + x2 * (-2.0 / 15 + x2 * (17.0 / 315 - x2 * 62.0 / 2835)))
    return np.where(np.abs(x) < 0.1, series, x - np.tanh(x))


def _x_minus_tan(x):
    """x − tan x without cancellation near 0."""
    x = _real_or_complex(x)
    x2 = x * x
    series = -x * x2 * (1.0 / 3 + x2 * (2.0 / 15 + x2 * (17.0 / 315 + x2 * 62.0 / 2835)))
    return np.where(np.abs(x) < 0.1, series, x - np.tan(x))


def wavenumbers(EI, H, m, omega):
    """p and q of a tensioned beam (see module docstring), cancellation-free."""
    a = H / (2.0 * EI)
    b = m * omega * omega / EI
    root = np.sqrt(a * a + b)
    p2 = a + root
    q2 = b / p2  # = root − a, without cancellation
    return np.sqrt(p2), np.sqrt(q2)


class BeamSegment:
    """Dynamic stiffness quantities of tensioned-beam segments at one ω each.

    All attributes are arrays over a batch of segments.

    Attributes
    ----------
    p, q, half : wavenumbers and half-length L/2
    sym : (a, b, d) entries of the symmetric 2×2 matrix [[a, b], [b, d]]
    anti : (e, f, h) entries of the antisymmetric 2×2 matrix
    translation_residual : R = eᵀ K e + m ω² L, e = (1, 0, 1, 0), computed
        without the cancellation of its two terms at low q L
    """

    def __init__(self, length, EI, H, m, omega):
        with np.errstate(divide="ignore"):  # a division by an exactly zero n_sym or n_anti is done again below
            self._compute(length, EI, H, m, omega)
        pole = (self.n_sym == 0) | (self.n_anti == 0)
        if np.any(pole):
            # ω exactly at a pole of a segment's stiffness (its clamped mode): the matrix would be infinite.
            # Evaluated a relative 1e-13 above it instead, count and matrix alike (a pole is no root of the
            # cable: the count on either side is right, the matrix finite).
            omega = np.where(pole, np.broadcast_to(omega, pole.shape) * (1 + 1e-13), omega)
            self._compute(length, EI, H, m, omega)

    def _compute(self, length, EI, H, m, omega):
        self.EI = EI
        self.half = half = 0.5 * length
        p, q = wavenumbers(EI, H, m, omega)
        self.p, self.q = p, q
        pl, ql = p * half, q * half
        T = np.tanh(pl)
        s, c = np.sin(ql), np.cos(ql)
        self.T, self.s, self.c = T, s, c
        ppqq = p * p + q * q
        pq = p * q
        n_sym = q * s + p * T * c
        # T q c − s p, whose leading terms (p q L/2 each) cancel on a short segment: written as
        # p (ql cos ql − sin ql) − q cos ql (pl − tanh pl), each part computed without cancellation.
        n_anti = p * _x_cos_minus_sin(ql) - q * c * _x_minus_tanh(pl)
        self.n_sym, self.n_anti = n_sym, n_anti
        k = EI / n_sym
        self.sym = (-k * pq * T * s * ppqq, -k * pq * n_anti, k * c * ppqq)
        k = EI / n_anti
        self.anti = (-k * pq * c * ppqq, k * pq * n_sym, -k * T * s * ppqq)
        num = p * p * T * _x_cos_minus_sin(ql) + q * q * s * _x_minus_tanh(pl)
        self.translation_residual = 2.0 * EI * pq * num / n_sym

    def matrix(self):
        """The 4×4 dynamic stiffness matrices, shape (..., 4, 4)."""
        a, b, d = self.sym
        e, f, h = self.anti
        K = np.empty(np.shape(a) + (4, 4), dtype=np.result_type(a, float))
        K[..., 0, 0] = K[..., 2, 2] = 0.5 * (a + e)
        K[..., 1, 1] = K[..., 3, 3] = 0.5 * (d + h)
        K[..., 0, 2] = K[..., 2, 0] = 0.5 * (a - e)
        K[..., 1, 3] = K[..., 3, 1] = 0.5 * (h - d)
        K[..., 0, 1] = K[..., 1, 0] = -0.5 * (b + f)
        K[..., 2, 3] = K[..., 3, 2] = 0.5 * (b + f)
        K[..., 0, 3] = K[..., 3, 0] = 0.5 * (b - f)
        K[..., 1, 2] = K[..., 2, 1] = 0.5 * (f - b)
        return K

    def translation_force(self):
        """K e for e = (1, 0, 1, 0): nodal forces of a unit rigid translation."""
        a, b, _ = self.sym
        return np.stack([a, -b, a, b], axis=-1)

    def clamped_count(self):
        """Natural frequencies below ω of the segment clamped at both ends.

        One root of Δ = 2pq(1 − cosh pL cos qL) + (p² − q²) sinh pL sin qL
        lies in each interval qL ∈ (iπ, (i+1)π), i ≥ 1 (checked against
        brute-force counting in the tests). Δ / cosh(pL) has the sign
        −(−1)^i at qL = iπ, so the root of interval i is passed when
        sign(Δ) = (−1)^i: J0 = i − ½(1 − (−1)^i sign Δ).
        """
        pL, qL = 2.0 * self.p * self.half, 2.0 * self.q * self.half
        p, q = self.p, self.q
        tanh_pl = np.tanh(pL)
        sech_pl = np.exp(-pL) * 2.0 / (1.0 + np.exp(-2.0 * pL))
        delta = 2 * p * q * (sech_pl - np.cos(qL)) + (p * p - q * q) * tanh_pl * np.sin(qL)
        i = np.floor(qL / np.pi)
        parity = 1.0 - 2.0 * (i % 2)
        passed = np.sign(delta) == parity
        return np.where(i >= 1, i - 1 + passed, 0).astype(np.int64)

    def shape_coefficients(self, v1, t1, v2, t2):
        """(A', B, C', D) of φ_h for end values, with A' = A cosh(pL/2) etc."""
        vs, ts = 0.5 * (v1 + v2), 0.5 * (t2 - t1)
        va, ta = 0.5 * (v2 - v1), 0.5 * (t1 + t2)
        p, q, T, s, c = self.p, self.q, self.T, self.s, self.c
        A = (q * s * vs + c * ts) / self.n_sym
        B = (p * T * vs - ts) / self.n_sym
        C = (q * c * va - s * ta) / self.n_anti
        D = (-p * va + T * ta) / self.n_anti
        return A, B, C, D

    def evaluate(self, coefficients, z):
        """φ_h at local centred coordinates z (|z| ≤ L/2), broadcast on z's last axis."""
        A, B, C, D = (np.asarray(x)[..., None] for x in coefficients)
        p, q, half = (np.asarray(x)[..., None] for x in (self.p, self.q, self.half))
        e1 = np.exp(p * (z - half))
        e2 = np.exp(-p * (z + half))
        norm = 1.0 + np.exp(-2.0 * p * half)
        return A * (e1 + e2) / norm + B * np.cos(q * z) + C * (e1 - e2) / norm + D * np.sin(q * z)


class StringSegment:
    """Taut-string segments (EI = 0): degrees of freedom (v1, v2)."""

    def __init__(self, length, H, m, omega):
        self.half = half = 0.5 * length
        self.H = H
        self.q = q = omega * np.sqrt(m / H)
        self.s, self.c = np.sin(q * half), np.cos(q * half)
        ql2 = 2.0 * q * half
        self.diag = H * q * np.cos(ql2) / np.sin(ql2)
        self.off = -H * q / np.sin(ql2)
        self.translation_residual = 2.0 * H * q * _x_minus_tan(q * half)

    def matrix(self):
        K = np.empty(np.shape(self.diag) + (2, 2), dtype=np.result_type(self.diag, float))
        K[..., 0, 0] = K[..., 1, 1] = self.diag
        K[..., 0, 1] = K[..., 1, 0] = self.off
        return K

    def translation_force(self):
        f = self.diag + self.off
        return np.stack([f, f], axis=-1)

    def clamped_count(self):
        """Modes nπ < qL of the fixed–fixed string."""
        qL = 2.0 * self.q * self.half
        return np.maximum(np.ceil(qL / np.pi) - 1, 0).astype(np.int64)

    def shape_coefficients(self, v1, v2):
        return 0.5 * (v1 + v2) / self.c, 0.5 * (v2 - v1) / self.s

    def evaluate(self, coefficients, z):
        S, A = (np.asarray(x)[..., None] for x in coefficients)
        q = np.asarray(self.q)[..., None]
        return S * np.cos(q * z) + A * np.sin(q * z)
