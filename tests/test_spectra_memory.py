"""Spectra in bounded memory: the banded computations equal the whole ones, and the peak stays bounded.

The ambient overview computes its Welch spectra a segment and a group of
channels at a time, and the cross-spectral sums of its degrees of freedom
band by band of frequency (recomputing each band's DFTs); the record's
DFT is kept in complex64. These tests pin that the results are those of
the direct computation (scipy's Welch, the full cross-spectral matrix in
complex128) and that find_peaks holds a bounded multiple of the record.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy import signal

from stcs_ident.core.record import Record
from stcs_ident.spectra import overview
from stcs_ident.spectra.peaks import find_peaks


def ambient(n: int, channels: int, fs: float = 200.0, seed: int = 0) -> np.ndarray:
    """Four lightly damped modes common to all channels (their shapes), plus sensor noise."""
    rng = np.random.default_rng(seed)
    modal = []
    for f in (7.0, 14.1, 21.3, 28.7):
        r, w = np.exp(-0.005 * 2 * np.pi * f / fs), 2 * np.pi * f / fs
        modal.append(signal.lfilter([1.0], [1.0, -2 * r * np.cos(w), r * r], rng.standard_normal(n)))
    x = np.array(modal).T @ np.sin(np.outer(np.arange(1, 5), np.linspace(0.1, 0.9, channels) * np.pi))
    return x + 0.1 * x.std() * rng.standard_normal(x.shape)


def direct_dof(x: np.ndarray, fs: float, floor: np.ndarray, dof: float) -> np.ndarray:
    """The coherent degrees of freedom from the full cross-spectral matrix (complex128, all in memory)."""
    nperseg = overview.welch_length(x.shape[0])
    step = nperseg // 2
    window = signal.windows.hann(nperseg, sym=False)
    n_segments = (x.shape[0] - nperseg) // step + 1
    segments = np.stack([x[k * step:k * step + nperseg] for k in range(n_segments)])  # (K, nperseg, C)
    segments = (segments - segments.mean(axis=1, keepdims=True)) * window[None, :, None]
    dft = np.fft.rfft(segments, axis=1) / np.sqrt(floor * np.sum(window**2) * fs / 2.0)[None]  # (K, F, C)
    csd = np.einsum("kfc,kfd->fcd", dft, dft.conj()) / n_segments
    trace = np.real(np.einsum("fcc->f", csd))
    square = np.maximum(np.sum(np.abs(csd) ** 2, axis=(1, 2)) - trace**2 / (dof / 2), trace**2 / x.shape[1])
    return dof * np.clip(trace**2 / square, 1.0, x.shape[1])


@pytest.mark.parametrize("channels", [3, 24])  # fewer channels than Welch segments (C x C sums), and more (Gram)
def test_the_banded_overview_equals_the_direct_computation(monkeypatch, channels):
    fs = 200.0
    x = ambient(40_000, channels, fs)
    whole = overview.ambient_overview(x, fs)
    monkeypatch.setattr(overview, "BLOCK_BYTES", 40_000)  # many bands, a few channels per step
    banded = overview.ambient_overview(x, fs)
    nperseg = overview.welch_length(x.shape[0])
    _, welch = signal.welch(x, fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2, axis=0)
    # The Welch spectra are float64 throughout: equal to scipy's to rounding.
    np.testing.assert_allclose(banded.channel_spectra, welch, rtol=1e-9)
    np.testing.assert_allclose(whole.channel_spectra, welch, rtol=1e-9)
    # The degrees of freedom come from complex64 sums (rounding 6e-8 relative, accumulated over C and K).
    reference = direct_dof(x, fs, whole.channel_floor, whole.dof)
    np.testing.assert_allclose(banded.combined_dof, reference, rtol=1e-4)
    np.testing.assert_allclose(whole.combined_dof, reference, rtol=1e-4)
    assert np.ptp(reference) > 0.5 * whole.dof  # the test sees coherent and incoherent bins, not a constant


def test_find_peaks_holds_a_bounded_multiple_of_the_record(monkeypatch):
    """Beside the record (mean removed in place), find_peaks holds at most 1.6 times its size: the DFT in
    complex64 (0.5), the overview's spectra (about 0.1 each) and the fits' temporaries. BLOCK_BYTES is made
    small so that the bound is the proportional one (on a record of gigabytes it is a quarter of it); the
    last 0.2 allow for the fixed-size blocks of the event scan. It was 20 times the record before."""
    fs = 200.0
    x = ambient(1_000_000, 8, fs)
    record = Record(x, fs, tuple(f"A{k}" for k in range(8)), np.linspace(1.0, 7.0, 8))
    monkeypatch.setattr(overview, "BLOCK_BYTES", 2**20)
    tracemalloc.start()
    try:
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        result = find_peaks(record, f_min=3.0, f_max=40.0, overwrite=True)
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    assert peak <= 1.6 * x.nbytes, f"{peak / x.nbytes:.2f} x the record"
    assert [round(p.frequency, 1) for p in result.peaks] == [7.0, 14.1, 21.3, 28.7]
    assert abs(record.acceleration.mean(axis=0)).max() < 1e-12 * abs(record.acceleration).max()  # in place


def test_find_peaks_leaves_the_record_alone_by_default():
    x = ambient(20_000, 3) + 5.0
    record = Record(x.copy(), 200.0, ("A", "B", "C"), np.array([2.0, 4.0, 6.0]))
    find_peaks(record, f_min=3.0, f_max=40.0)
    np.testing.assert_array_equal(record.acceleration, x)
