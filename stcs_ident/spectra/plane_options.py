"""The options of the planes and of the peaks that are not the cable's (:mod:`.plane_analysis`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

from .option_checks import OptionGroup, count, fraction, positive, tuple_of

__all__ = ["PlaneOptions"]


def _frequencies(value) -> str | None:
    return None if value == () else tuple_of(positive)(value)


@dataclass(frozen=True)
class PlaneOptions(OptionGroup):
    """The two planes and what is not the cable's (:mod:`.plane_analysis`, :mod:`.structural`); used only for a
    record whose channels have directions. Not one of :class:`.options.PickingOptions`'s groups (those tune the
    picking of one set of channels); :func:`.pipeline.analyse_test` takes it as ``plane_options`` and the
    result records it.

    Attributes
    ----------
    structural : tuple of float
        Known frequencies of the structure (deck, pylon), Hz: a peak within 3σ of one of them or of a
        harmonic of one is structural, never numbered (default none).
    leak_ratio : float
        A peak seen in both planes at one frequency (within 3σ) is one mode leaking through a misaligned
        sensor when the weaker plane's amplitude is below this fraction of the stronger's (0.15: a sensor
        turned by up to 8.6°, sin 8.6° = 0.15); above it, both planes carry a mode (two modes, kept apart).
    min_mac : float
        A numbered peak whose operating shape has a modal assurance criterion below this against the
        model's shape of its mode, where that is meaningful (two positions or more in the plane, the model's
        shape not at a node of them all), is structural (0.9: on simulated bridge records, 3 positions,
        30 dB, a correctly numbered cable mode's MAC was above 0.955 in 99.9 % of 860 modes, median 0.99994;
        a deck mode numbered at 8 % from the cable mode it replaced had 0.86).
    axial_ratio : float
        A peak whose largest amplitude on the axial channels reaches this fraction of its largest transverse
        amplitude moves the anchorage (structural; 0.3: a cable's own mode moves a sensor along the chord by
        about the slope of its sag profile times its transverse motion, a few per cent).
    max_harmonic : int
        Harmonics of a structural frequency considered, up to this order (5).
    """

    structural: tuple[float, ...] = ()
    leak_ratio: float = 0.15
    min_mac: float = 0.9
    axial_ratio: float = 0.3
    max_harmonic: int = 5

    _name: ClassVar[str] = "planes"
    _checks: ClassVar[dict[str, Callable]] = {
        "structural": _frequencies, "leak_ratio": fraction, "min_mac": fraction,
        "axial_ratio": positive, "max_harmonic": count,
    }

    def summary(self) -> dict:
        """Plain data for JSON (the structural frequencies as a list)."""
        return {"structural": list(self.structural), "leak_ratio": self.leak_ratio, "min_mac": self.min_mac,
                "axial_ratio": self.axial_ratio, "max_harmonic": self.max_harmonic}
