"""The result of :func:`.peaks.find_peaks`: the peaks, and the spectra they were found in."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..core.result import Result
from .options import PickingOptions

__all__ = ["Peak", "PeakResult"]


@dataclass(frozen=True)
class Peak:
    """One modal peak.

    Parameters
    ----------
    frequency : float
        Undamped natural frequency f_n = |s|/2π of the fitted pole, Hz.
    uncertainty : float
        1σ of ``frequency`` (Fisher information of the fit), Hz.
    damping : float or None
        Damping ratio ζ (None when the fit failed and the overview peak is
        reported instead).
    damping_uncertainty : float or None
        1σ of ``damping``.
    channels : tuple of str
        Channels whose own spectrum shows the peak ≥ 6 dB above its floor.
    amplitude : ndarray (n_channels,)
        Per channel, signed by the phase relative to the largest entry
        (so it is the sampled mode shape): for free decays, the amplitude
        of the mode at the start of the strongest event, m/s²; for ambient
        records, the rms modal acceleration, m/s².
    snr_db : float
        Height of the peak above the floor of the combined spectrum, dB.
    channel_snr_db : ndarray (n_channels,)
        Height above each channel's floor, dB.
    misfit : float
        Of an ambient fit, the misfit-robust 1σ of the frequency over the Fisher information's (about 1 where
        one mode describes its band; 1 for other fits).
    second_pole : (frequency Hz, 1σ Hz, statistic) or None
        Of an ambient fit that misfits its band, a second resonance the band holds beside the peak's
        (:mod:`.two_poles`: its undamped frequency, a 1σ of at least its half-power half-width, and the
        likelihood-ratio statistic 2 (ℓ₁ − ℓ₂) of two poles against one); None where one pole describes it.
    """

    frequency: float
    uncertainty: float
    damping: float | None
    damping_uncertainty: float | None
    channels: tuple[str, ...]
    amplitude: np.ndarray
    snr_db: float
    channel_snr_db: np.ndarray = field(repr=False)
    misfit: float = field(default=1.0, repr=False)
    second_pole: tuple[float, float, float] | None = field(default=None, repr=False)


class PickingResult(Result):
    """The common face of the spectra step's results: their ``settings`` are the picking options they were
    made with (an ``options`` field), and they have no notes yet."""

    options: PickingOptions

    @property
    def settings(self) -> PickingOptions:
        """How the result was made: its picking options (``options``)."""
        return self.options

    @property
    def notes(self) -> tuple:
        """``()``: the peak picking has no notes yet."""
        return ()


@dataclass(frozen=True, repr=False)
class PeakResult(PickingResult):
    """Result of :func:`find_peaks`.

    ``tables()`` holds ``peaks`` (the main table, :meth:`to_dataframe`).

    Parameters
    ----------
    peaks : list of Peak
        Ordered by frequency.
    kind : str
        "impulse" or "ambient".
    events : list of (float, float)
        Free-decay segments used, (start, end) in s from the record start
        (empty for ambient records).
    frequency_axis : ndarray (n_freq,), Hz
    combined_spectrum : ndarray (n_freq,)
        Mean over channels of each channel's spectrum over its noise floor
        (about 1 where there is only noise).
    combined_floor : ndarray (n_freq,)
        Floor of ``combined_spectrum`` (about 1).
    channel_spectra : ndarray (n_freq, n_channels)
        One-sided PSD, (m/s²)²/Hz (per-event periodograms averaged over
        events for impulse records, Welch for ambient).
    channel_floor : ndarray (n_freq, n_channels)
        Noise floor of each channel spectrum.
    channel_names : tuple of str
    threshold : ndarray (n_freq,)
        Detection threshold on combined / floor (linear; it depends on the
        local degrees of freedom): a peak must reach floor × threshold.
    options : PickingOptions
        The options the peaks were picked with (how the result was made).
    """

    peaks: list[Peak]
    kind: str
    events: list[tuple[float, float]]
    frequency_axis: np.ndarray
    combined_spectrum: np.ndarray
    combined_floor: np.ndarray
    channel_spectra: np.ndarray
    channel_floor: np.ndarray
    channel_names: tuple[str, ...]
    threshold: np.ndarray
    options: PickingOptions = field(default_factory=PickingOptions)

    main_table = "peaks"

    def tables(self) -> dict[str, pd.DataFrame]:
        """``peaks``: one row per peak (:meth:`to_dataframe`)."""
        return {"peaks": self.to_dataframe()}

    def headline(self) -> str:
        """How many peaks, in which band, from which kind of record."""
        if not self.peaks:
            return f"no peak ({self.kind} record, {len(self.channel_names)} channels)"
        low, high = self.peaks[0].frequency, self.peaks[-1].frequency
        return (f"{len(self.peaks)} peaks from {low:.4g} to {high:.4g} Hz ({self.kind} record, "
                f"{len(self.channel_names)} channels)")

    def to_dataframe(self) -> pd.DataFrame:
        """One row per peak: ``frequency_Hz``, ``uncertainty_Hz`` (1σ), ``damping_ratio`` and
        ``damping_ratio_uncertainty`` (NaN where the fit failed), ``snr_db``, ``channels`` (joined by ``;``) and
        the amplitude per channel, ``amplitude_m_per_s2[<channel>]``."""
        rows = []
        for p in self.peaks:
            row = {
                "frequency_Hz": p.frequency,
                "uncertainty_Hz": p.uncertainty,
                "damping_ratio": p.damping,
                "damping_ratio_uncertainty": p.damping_uncertainty,
                "snr_db": p.snr_db,
                "channels": ";".join(p.channels),
            }
            row.update({f"amplitude_m_per_s2[{name}]": a for name, a in zip(self.channel_names, p.amplitude)})
            rows.append(row)
        columns = ["frequency_Hz", "uncertainty_Hz", "damping_ratio", "damping_ratio_uncertainty", "snr_db", "channels"]
        columns += [f"amplitude_m_per_s2[{name}]" for name in self.channel_names]
        return pd.DataFrame(rows, columns=columns)

    def summary(self) -> dict:
        """Plain data (JSON-serialisable): kind, events and per-peak lists, ordered by frequency, and the options."""
        return {
            "kind": self.kind,
            "events": [list(e) for e in self.events],
            "frequencies": [p.frequency for p in self.peaks],
            "uncertainty": [p.uncertainty for p in self.peaks],
            "damping": [p.damping for p in self.peaks],
            "damping_uncertainty": [p.damping_uncertainty for p in self.peaks],
            "snr_db": [p.snr_db for p in self.peaks],
            "channels": [list(p.channels) for p in self.peaks],
            "options": self.options.summary(),
        }
