"""Residual pass (ambient records): peaks that the fitted modes leave unexplained.

Where broad resonances fill a band, the noise floor follows the valleys
between them (:mod:`.floor`) and a weak mode between two stronger ones
may rise above the valley beside it by less than the detection threshold
asks of a peak's prominence: it is not detected, and its neighbour's fit
absorbs it. Once the detected modes are fitted, their expected Welch
spectra are known, so what remains can be tested against them.

Model spectrum
    For each fitted mode, the autocovariance a_c² e^{−σ|τ|} cos(2π f_d τ)
    in channel c (a_c the fitted rms modal acceleration), and the expected
    Welch spectrum of the sum exactly: the autocovariance times the
    autocorrelation of the Hann window, transformed (so a mode narrower
    than a Welch cell has the window's line shape). The channel's
    expected spectrum is its noise floor plus that of the modes (where
    resonances fill the band the floor already holds part of their
    tails: the test is then conservative).

Detection
    The Welch spectrum over that expectation is, where the model is
    right, a chi-squared variable over its degrees of freedom: its
    combined (mean over channels) and largest-channel values are tested
    against the overview's thresholds (:func:`.overview.detection_threshold`)
    with their own share of the false-alarm probability, away from the
    fitted modes (a half-power width) and from the candidates already
    tried. No prominence is asked: the known resonances are in the
    expectation. What passes is only a proposal (misfit of a fitted
    mode also leaves excess): it is reported only if its fit with the
    others confirms a mode (:mod:`.refine`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import signal
from scipy.fft import irfft, rfft

from .overview import Candidate, Overview, _candidate, detection_threshold

__all__ = ["model_spectra", "residual_candidates"]

RESIDUAL_FALSE_ALARM_SHARE = 0.5  # of the record's false-alarm probability, on top of the overview's
CLEARANCE_WIDTHS = 1.0  # a residual peak within this many half-power widths of a fitted mode is its misfit


def model_spectra(overview: Overview, sampling_rate: float, modes: list[tuple[float, float, np.ndarray]]) -> np.ndarray:
    """Expected Welch spectra (n_freq, n_channels) of fitted modes (frequency f_n Hz, decay rate 1/s, rms per channel).

    The overview's grid gives the Welch segment length; the spectra are
    one-sided PSD, (m/s²)²/Hz, as ``overview.channel_spectra``.
    """
    n_freq, n_channels = overview.channel_spectra.shape
    if not modes:
        return np.zeros((n_freq, n_channels))
    df = overview.frequency[1] - overview.frequency[0]
    length = int(round(sampling_rate / df))
    window = signal.windows.hann(length, sym=False)
    lag_weight = irfft(np.abs(rfft(window, 2 * length)) ** 2, 2 * length)[:length]  # Σ_n w[n] w[n+τ]
    lag = np.arange(length) / sampling_rate
    frequency = np.array([m[0] for m in modes])
    decay = np.array([m[1] for m in modes])
    power = np.array([np.asarray(m[2], dtype=float) ** 2 for m in modes])  # (n_modes, n_channels)
    damped = np.sqrt(np.maximum((2 * np.pi * frequency) ** 2 - decay**2, 0.0))
    shapes = np.exp(-np.outer(lag, decay)) * np.cos(np.outer(lag, damped))  # (length, n_modes)
    covariance = (shapes @ power) * lag_weight[:, None]  # (length, n_channels)
    # Σ over lags −(L−1) … L−1 of an even sequence: twice the DFT of lags 0 … L−1, less lag 0.
    two_sided = 2.0 * rfft(covariance, axis=0).real - covariance[:1]
    psd = two_sided / (np.sum(window**2) * sampling_rate)
    psd[1:-1] *= 2.0
    return np.maximum(psd[:n_freq], 0.0)


def residual_candidates(
    overview: Overview,
    sampling_rate: float,
    modes: list[tuple[float, float, np.ndarray]],
    tried: list[Candidate],
    f_min: float,
    f_max: float,
) -> list[Candidate]:
    """Proposals where the Welch spectrum exceeds the fitted modes' expectation (see the module docstring).

    Parameters
    ----------
    overview : Overview
        An ambient (Welch) overview.
    sampling_rate : float
        Hz.
    modes : list of (frequency, decay rate, rms amplitude per channel)
        The fitted modes.
    tried : list of Candidate
        Candidates already fitted: no proposal within their half-power width.
    f_min, f_max : float
        Band searched, Hz.

    Returns
    -------
    list of Candidate
        Proposals (``proposal=True``) in frequency order, on the overview's
        grid, their ``spectrum`` the overview's combined one.
    """
    f = overview.frequency
    df = f[1] - f[0]
    lo = max(int(np.ceil(f_min / df)), 3 * overview.cell)
    hi = min(int(np.floor(f_max / df)), f.size - 2)
    if hi <= lo:
        return []
    n_cells = max(hi - lo, 1) // overview.cell
    expected = overview.channel_floor + model_spectra(overview, sampling_rate, modes)
    ratio = overview.channel_spectra / expected
    false_alarm = RESIDUAL_FALSE_ALARM_SHARE * 1e-4
    statistics = [(ratio.mean(axis=1), detection_threshold(overview, n_cells, false_alarm=false_alarm),
                   overview.combined_dof)]
    if ratio.shape[1] > 1:
        statistics.append((ratio.max(axis=1), detection_threshold(
            overview, n_cells, per_channel=True, false_alarm=false_alarm), overview.channel_dof))
    found: list[Candidate] = []
    for statistic, threshold, dof in statistics:
        index, _ = signal.find_peaks(statistic, distance=max(1, overview.cell))
        index = index[(index >= lo) & (index <= hi)]
        for k in index[statistic[index] >= threshold[index]]:
            c = _candidate(overview, statistic, int(k), threshold[k], dof[k])
            if _clear(c, modes, tried + found):
                found.append(replace(c, spectrum=overview.combined / overview.combined_floor, proposal=True))
    return sorted(found, key=lambda c: c.frequency)


def _clear(c: Candidate, modes, others: list[Candidate]) -> bool:
    """Away from every fitted mode (CLEARANCE_WIDTHS half-power widths) and from every candidate's peak."""
    for frequency, decay, _ in modes:
        if abs(c.frequency - frequency) <= CLEARANCE_WIDTHS * max(decay / np.pi, c.half_power_width):
            return False
    return all(abs(c.frequency - k.frequency) > max(c.half_power_width, k.half_power_width) for k in others)
