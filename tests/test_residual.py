"""Residual pass of ambient records: the fitted modes' expected Welch spectrum, and what it leaves.

Synthetic records from known parameters and a seeded generator: a mode is
the real part of a complex first-order autoregression with the pole
r = exp((−σ + iω_d)Δt), whose autocovariance is exactly the model's
a² e^{−σ|τ|} cos(ω_d τ).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import welch

from stcs_ident.spectra.overview import ambient_overview
from stcs_ident.spectra.residual import model_spectra, residual_candidates


def pole_process(frequency: float, zeta: float, rms: float, fs: float, n: int, rng) -> np.ndarray:
    """Real part of z[n] = r z[n−1] + e[n] (complex white e), scaled to the rms `rms`."""
    omega = 2 * np.pi * frequency
    r = np.exp((-zeta * omega + 1j * omega * np.sqrt(1 - zeta**2)) / fs)
    e = rng.standard_normal(n) + 1j * rng.standard_normal(n)
    z = np.zeros(n, complex)
    z[0] = e[0] / np.sqrt(1 - abs(r) ** 2)  # stationary start
    for k in range(1, n):
        z[k] = r * z[k - 1] + e[k]
    x = z.real
    return x * rms / np.sqrt(1.0 / (1 - abs(r) ** 2))  # var(Re z) = E|e|²/2 / (1 − |r|²) = 1 / (1 − |r|²)


def test_model_spectrum_is_the_expected_welch_spectrum():
    """Two modes (one narrower than a Welch cell), two channels: Welch over model ≈ 1 at and around each peak.

    The Welch average of 1 h (about 450 segments) scatters by 1/√450 ≈ 5 % per bin; the mean over the
    ±3-cell neighbourhood of each peak, by about 2 %: 6 % allowed.
    """
    rng = np.random.default_rng(3)
    fs, n = 64.0, 64 * 3600
    modes = [(5.0, 0.01, np.array([1.0, 0.5])), (11.0, 0.0005, np.array([0.2, 0.8]))]
    x = np.zeros((n, 2))
    for frequency, zeta, rms in modes:
        x += pole_process(frequency, zeta, 1.0, fs, n, rng)[:, None] * rms[None, :]
    overview = ambient_overview(x[: n // 16], fs)  # the grid of a 225 s record's overview
    spectra = welch_on_grid(x, fs, overview.frequency)
    expected = model_spectra(overview, fs, [(f, z * 2 * np.pi * f, a) for f, z, a in modes])
    df = overview.frequency[1] - overview.frequency[0]
    for frequency, _, _ in modes:
        k = round(frequency / df)
        ratio = spectra[k - 3 : k + 4].mean(axis=0) / expected[k - 3 : k + 4].mean(axis=0)
        np.testing.assert_allclose(ratio, 1.0, rtol=0.06)
    # Total power of each channel: the sum of the modes' mean squares (1 % for the finite grid and scatter).
    total = expected.sum(axis=0) * df
    np.testing.assert_allclose(total, sum(a**2 for _, _, a in modes), rtol=0.01)


def welch_on_grid(x: np.ndarray, fs: float, frequency: np.ndarray) -> np.ndarray:
    """SciPy's Welch spectrum (Hann, 50 % overlap) with the overview's segment length."""
    nperseg = round(fs / (frequency[1] - frequency[0]))
    _, p = welch(x, fs=fs, nperseg=nperseg, axis=0)
    return p


def test_weak_mode_between_fitted_ones_is_proposed_and_nothing_else():
    """Three broad modes (ζ = 2 %), the middle one 6 dB weaker than its neighbours, white sensor noise.

    With only the outer two as fitted modes, the residual proposes the middle one; with all three fitted,
    it proposes nothing (the model explains the spectrum).
    """
    rng = np.random.default_rng(11)
    fs, n = 32.0, 32 * 300
    truth = [(4.0, 0.02, 1.0), (4.6, 0.02, 0.5), (5.2, 0.02, 1.0)]
    x = np.zeros((n, 3))
    shapes = np.array([[1.0, 0.7, 0.3], [0.4, -0.9, 0.8], [0.9, 0.2, -0.6]])
    for (frequency, zeta, rms), shape in zip(truth, shapes):
        x += pole_process(frequency, zeta, rms, fs, n, rng)[:, None] * shape[None, :]
    x += 0.02 * rng.standard_normal(x.shape)
    overview = ambient_overview(x, fs)
    fitted = [(f, z * 2 * np.pi * f, rms * shape) for (f, z, rms), shape in zip(truth, shapes)]
    outer = [fitted[0], fitted[2]]
    proposed = residual_candidates(overview, fs, outer, [], 1.0, 10.0)
    assert [round(c.frequency, 1) for c in proposed] == [4.6]
    assert proposed[0].proposal
    assert residual_candidates(overview, fs, fitted, [], 1.0, 10.0) == []
