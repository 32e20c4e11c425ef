"""Is the nominal model on the scale of the record's peaks? Checked from the peaks alone, before numbering.

The numbering (:mod:`.numbering`) matches the peaks with the nominal family
within a window of tensions (0.6–1.5 × the stated one): a unit slip in the
campaign (a tension in kN, a mass per length in g/m) or a sampling rate 2×
off moves every peak far outside that window, and the numbering then bends
the numbers to the wrong family (a record of 100 Hz read at 200 Hz: its
peaks numbered 2, 4, 6, … at MAC 0.0–0.6). Here the peaks of each plane are
numbered from their own spacing (:func:`.harmonic.harmonic_series`, the
nominal scale unused) and compared with the nominal family at those numbers:
:class:`ScaleCheck` holds the ratio; outside ×/÷ :data:`SCALE_BAND` the
nominal model and the record disagree by more than any correct campaign's
stated tension allows (f ∝ √T: a ratio of 1.3 is a tension 1.7× off), and
the spectra's numbers are doubtful. ``identify``, ``diagnose`` and ``track``
refuse such a test, naming the field and the likely slip
(:mod:`stcs_ident.identify.plausibility`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .harmonic import HarmonicSeries, harmonic_series

__all__ = ["SCALE_BAND", "ScaleCheck", "check_scale", "round_factor", "shapes_confirm"]

#: Largest plausible ratio (either way) of measured to nominal frequencies: the plausibility check's band
#: (a stated tension 0.6–1.7 × the truth gives a ratio within 1.3; a unit slip is √1000 ≈ 31.6 or more).
SCALE_BAND = 1.3
#: Fewest peaks the series must number for its scale to be trusted (two peaks fit many spacings).
MIN_PEAKS = 3
#: The lowest numbered modes whose ratios to the nominal family give the scale (more than one, so that one mode
#: moved by a hidden mass or by sag does not decide).
LOWEST = 3
#: A plane whose numbered modes' median MAC is this or more, over at least :data:`MIN_PEAKS` modes with a meaningful
#: MAC, has its numbers confirmed by the shapes, and is not checked (:func:`shapes_confirm`): the slips the check is
#: for give 0.0-0.6 (a tension in kN: 0.48, 0.04, 0.00; a rate 2x off: 0.00-0.59), a correct campaign's modes
#: 0.95-1.00; and the series of a plane whose deck-mode peaks stand beside the cable's may be the sub-harmonic
#: one, which numbers both (a biaxial stay's out-of-plane peaks gave a ratio of 0.51, its MACs 0.9 and more).
CONFIRMING_MAC = 0.8
#: Sampling-rate slips recognised in a ratio (a rate typed 2×, 10× off, or the rate of another logger).
RATE_FACTORS = (2.0, 0.5, 4.0, 0.25, 5.0, 0.2, 10.0, 0.1, 100.0, 0.01, 1000.0, 0.001)


@dataclass(frozen=True)
class ScaleCheck:
    """One plane's peaks numbered from their own spacing, against the nominal family.

    Attributes
    ----------
    plane : str
        ``"in"`` or ``"out"``.
    series : HarmonicSeries
        The peaks' own series (its ``modes`` in the order of ``frequencies``).
    frequencies : ndarray
        The plane's peaks, Hz (numbered or not by the nominal numbering; structural peaks left out).
    ratio : float
        Measured / nominal frequency of the same mode, the geometric mean over the series' :data:`LOWEST`
        lowest numbered modes (where a slip shows whole: a stiff member's higher modes are set by EI, which no
        tension or mass slip moves; NaN when nothing is numbered).
    mode : int
        The lowest mode the series numbers.
    measured, nominal : float
        Its measured and nominal frequencies, Hz.
    """

    plane: str
    series: HarmonicSeries
    frequencies: np.ndarray
    ratio: float
    mode: int
    measured: float
    nominal: float

    @property
    def conclusive(self) -> bool:
        """Whether the series is sure enough to judge the nominal scale: at least :data:`MIN_PEAKS` numbered, no
        other spacing almost as good, a finite ratio."""
        return (not self.series.ambiguous and self.series.n_assigned >= MIN_PEAKS and math.isfinite(self.ratio)
                and self.ratio > 0)

    @property
    def implausible(self) -> bool:
        """Conclusive, and the ratio outside ×/÷ :data:`SCALE_BAND`."""
        return self.conclusive and not 1 / SCALE_BAND <= self.ratio <= SCALE_BAND

    def sentence(self) -> str:
        """``the peaks form a harmonic series 2.00× the nominal one (mode 1 at 1.74 Hz, nominal 0.870 Hz)``."""
        word = "out-of-plane " if self.plane == "out" else ""
        return (f"the {word}peaks form a harmonic series {_times(self.ratio)} the nominal one (mode {self.mode} at "
                f"{self.measured:.4g} Hz, nominal {self.nominal:.4g} Hz)")

    def summary(self) -> dict:
        """Plain data for JSON."""
        return {"plane": self.plane, "ratio": float(self.ratio), "mode": int(self.mode),
                "measured": float(self.measured), "nominal": float(self.nominal),
                "fundamental": float(self.series.fundamental), "inharmonicity": float(self.series.inharmonicity),
                "numbered": self.series.n_assigned, "conclusive": self.conclusive,
                "implausible": self.implausible}


def _times(ratio: float) -> str:
    return f"{ratio:.3g}×" if ratio >= 1 else f"1/{1 / ratio:.3g}×"


def round_factor(ratio: float, tolerance: float = 0.03) -> float | None:
    """The factor of :data:`RATE_FACTORS` within ``tolerance`` (relative) of ``ratio``, else None: a ratio of
    exactly such a factor is a sampling rate typed wrong, not a tension (which is never off by exactly 2)."""
    for k in RATE_FACTORS:
        if abs(ratio / k - 1) <= tolerance:
            return k
    return None


def shapes_confirm(macs, planes, plane: str) -> bool:
    """Whether the numbered modes of ``plane`` (``macs`` and ``planes`` per mode) confirm their numbers by their
    shapes (:data:`CONFIRMING_MAC`)."""
    if macs is None:
        return False
    values = np.asarray(macs, float)[np.asarray(planes) == plane]
    values = values[np.isfinite(values)]
    return bool(values.size >= MIN_PEAKS and np.median(values) >= CONFIRMING_MAC)


def check_scale(plane: str, frequencies: Sequence[float], uncertainties: Sequence[float],
                nominal: Callable[[int], np.ndarray]) -> ScaleCheck | None:
    """The :class:`ScaleCheck` of one plane's peaks; ``nominal(n)`` gives the nominal family's first ``n``
    frequencies in that plane (Hz). None without peaks."""
    f = np.asarray(frequencies, float)
    series = harmonic_series(f, uncertainties)
    if series is None:
        return None
    numbered = series.modes > 0
    if not numbered.any():
        return ScaleCheck(plane, series, f, math.nan, 0, math.nan, math.nan)
    n = series.modes[numbered]
    family = np.asarray(nominal(int(n.max())), float)
    model = family[n - 1]
    ratios = f[numbered] / model
    low = np.argsort(n)[:LOWEST]
    lowest = int(low[0])
    return ScaleCheck(plane, series, f, float(np.exp(np.mean(np.log(ratios[low])))), int(n[lowest]),
                      float(f[numbered][lowest]), float(model[lowest]))
