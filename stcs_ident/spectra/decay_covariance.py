"""Covariance of a free-decay fit when the band noise is not white: sensor floor plus the mode's forced response.

Used by :mod:`.decay_fit`. Ambient loading that goes on under a decay adds
the mode's own random response to the sensor noise; the fit's covariance
is then the sandwich of its estimating equation under the noise model
diag(n) + L_k M estimated from the residuals. Each band (one event) comes
with ``columns``, the decay's DFT column g(k) of the fitted pole z = sΔt
at the band's bins, and ``state`` holds the fit's residuals,
coefficients and projected Jacobian per band.
"""

from __future__ import annotations

import numpy as np
from scipy import optimize

__all__ = ["forced_response_covariance", "noise_model", "stationary_shape"]


def stationary_shape(z: complex, phase: np.ndarray, n: int) -> np.ndarray:
    """Expected |X[k]|² (up to scale) of the mode's stationary random response in an N-sample segment.

    Re(2G(u) − 1), u = exp(z − iφ), G(u) = Σ_{τ<N} (1 − τ/N) u^τ: the
    Lorentzian of the pole convolved with the segment's Fejér kernel (the
    debiased Whittle mean of :mod:`.ambient_fit`, its dispersive part left out).
    """
    log_u = z - 1j * phase
    u = np.exp(log_u)
    one_minus = -np.expm1(log_u)
    g = 1.0 / one_minus - u * (-np.expm1(n * log_u)) / (n * one_minus**2)
    return np.maximum(np.real(2.0 * g - 1.0), 0.0)


def noise_model(z: complex, columns: list, state, bands: list) -> tuple[np.ndarray, np.ndarray, list]:
    """White floor n_c and forced-response matrix M (C × C) of the band noise Σ_k = diag(n) + L_k M.

    Ambient loading that goes on under a decay leaves, besides the sensor
    noise, the mode's own random response: a Lorentzian L_k of the fitted
    pole in every channel, common to all (M is the cross-spectral matrix
    of that response, rank one for one mode). Both are estimated from the
    residuals by moments that allow for what the fit removed: the
    residual of bin k has E|r_kc|² = n_c (1 − h_k) + M_cc Σ_j |(I − P)_kj|² L_j
    (P the projection on the model's linear columns), and its
    cross-products between channels only the second term. M is then
    projected on the positive semi-definite matrices.
    """
    lev, lor, res_all, shapes = [], [], [], []
    for band, res, g in zip(bands, state.residuals, columns):
        basis = np.column_stack([g, band.background])
        q, _ = np.linalg.qr(basis)
        shape = stationary_shape(z, band.phase, band.n_samples)
        complement_diagonal, complement_lorentzian = _complement_moments(q, shape)
        lev.append(complement_diagonal)
        lor.append(complement_lorentzian)
        res_all.append(res)
        shapes.append(shape)
    a, b, r = np.concatenate(lev), np.concatenate(lor), np.concatenate(res_all)
    n_channels = r.shape[1]
    power = np.abs(r) ** 2
    floor, forced = np.zeros(n_channels), np.zeros(n_channels)
    design = np.column_stack([a, b])
    for c in range(n_channels):
        # Moments weighted by the inverse expected power (|r|² scatters in proportion to its mean).
        weight = np.ones(a.size)
        for _ in range(3):
            coef, _ = optimize.nnls(design * weight[:, None], power[:, c] * weight)
            expected = design @ coef
            weight = 1.0 / np.maximum(expected, 1e-12 * max(expected.max(), np.finfo(float).tiny))
        floor[c], forced[c] = coef
    matrix = np.diag(forced).astype(complex)
    if n_channels > 1 and np.any(forced > 0):
        weight = b / np.maximum(a * floor.mean() + b * forced.mean(), np.finfo(float).tiny) ** 2
        cross = (r * (weight * b)[:, None]).T @ r.conj() / max(float(np.sum(weight * b * b)), np.finfo(float).tiny)
        matrix = cross.copy()
        matrix[np.diag_indices(n_channels)] = forced
        values, vectors = np.linalg.eigh(0.5 * (matrix + matrix.conj().T))
        matrix = (vectors * np.maximum(values, 0.0)) @ vectors.conj().T
    # A floor the forced term explains away entirely is still not zero (the ratios below divide by it).
    floor = np.maximum(floor, 1e-9 * power.mean(axis=0) + np.finfo(float).tiny)
    return floor, matrix, shapes


def _complement_moments(q: np.ndarray, shape: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """diag(I − P) and |I − P|² @ shape (elementwise square) for the projection P = q qᴴ, q (m, p) orthonormal.

    Without forming the m × m matrices (a wide band of a long record has
    m of ten thousand bins: 1.6 GB and a minute per fit): with h = diag P,
    |(I − P)_kj|² = δ_kj (1 − 2 h_k) + |P_kj|², and Σ_j |P_kj|² s_j =
    q_k G q_kᴴ with G = qᴴ diag(s) q (p × p). Equal to the dense products
    to rounding; O(m p²).
    """
    h = np.sum(q.real**2 + q.imag**2, axis=1)
    gram = q.conj().T @ (shape[:, None] * q)
    quadratic = np.sum(np.real((q @ gram) * q.conj()), axis=1)
    return 1.0 - h, np.maximum(shape * (1.0 - 2.0 * h) + quadratic, 0.0)


def forced_response_covariance(z: complex, columns: list, state, bands: list, weights: np.ndarray,
                               jtj: np.ndarray) -> tuple[np.ndarray, float]:
    """Covariance of (f_d, σ) under the band noise diag(n) + L_k M (:func:`noise_model`), and the forced ratio.

    The estimate solves Re Σ_k J_kᴴ W r_k = 0, so to first order its
    covariance is the sandwich F⁻¹ (½ Re Σ_k J_kᴴ W Σ_k W J_k) F⁻¹ with
    F = Re Σ J^H W J: (2F)⁻¹, the Fisher information's bound, when the
    noise is white and independent between channels (M = 0), larger when
    a random response of the mode sits under the decay (it is coloured,
    concentrated where the frequency is decided, and common to all
    channels). The forced ratio is Σ L_k tr(M N⁻¹) over Σ |g_k|² bᴴ N⁻¹ b
    (N = diag(n)): the random response's power in the band over the decay's.
    """
    floor, matrix, shapes = noise_model(z, columns, state, bands)
    forced_power = sum(float(shape.sum()) for shape in shapes) * float(np.sum(np.real(np.diag(matrix)) / floor))
    decay_power = sum(float(np.sum(np.abs(g) ** 2)) * float(np.sum(np.abs(coef[0]) ** 2 / floor))
                      for g, coef in zip(columns, state.coefficients))
    meat = np.zeros((2, 2))
    for jac, shape in zip(state.jacobian, shapes):
        wj = jac * weights[None, :, None]  # (m, C, 2)
        white = np.einsum("mci,c,mcj->ij", wj.conj(), floor, wj)
        forced = np.einsum("m,mci,cd,mdj->ij", shape, wj.conj(), matrix, wj)
        meat += 0.5 * np.real(white + forced)
    inverse = np.linalg.inv(jtj)
    return inverse @ meat @ inverse, forced_power / max(decay_power, np.finfo(float).tiny)
