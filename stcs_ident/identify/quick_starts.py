"""Where the quick tension's exact fit starts, and when its EI is not seen (:mod:`.quick`).

The starts come from the pinned tensioned beam, (f_n/n)² = T/(4 m l²) + π² EI n²/(4 m l⁴) (docs/model.md):
its intercept gives the tension, its slope EI.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.errors import BoundError

__all__ = ["EI_start", "at_lower_EI", "tension_start"]


def EI_start(length, mass, freqs, modes, tension) -> float:
    """A start for EI: the slope of (f_n/n)² against n² is π² EI/(4 m l⁴) on a pinned beam; where that slope is
    not positive, EI for ξ = 100."""
    slope = np.polyfit(modes.astype(float) ** 2, (freqs / modes) ** 2, 1)[0]
    guess = 4 * mass * length**4 * slope / math.pi**2
    fallback = tension * length**2 / 100.0**2
    return float(guess) if guess > 0 and math.isfinite(guess) else fallback


def tension_start(length, mass, freqs, modes, EI, fallback) -> float:
    """A start for the exact fit's tension from the pinned tensioned beam, (f_n/n)² = T/(4 m l²) + π² EI n²/(4 m l⁴)
    (docs/model.md): with EI unknown and two modes or more, the intercept of the straight line through the
    modes; with EI given (or one mode), the lowest mode with EI's share removed. The mean of the taut-string
    tensions of every mode, the start before, was 1.6x the truth on a stiff hanger (ξ 16, eleven modes), far
    enough that the fit refused its own start as implausible. ``fallback`` where the line gives no positive
    tension."""
    n = modes.astype(float)
    if EI is None and freqs.size >= 2 and np.unique(n).size >= 2:
        intercept = np.polyfit(n**2, (freqs / n) ** 2, 1)[1]
        guess = 4 * mass * length**2 * intercept
    else:
        k = int(np.argmin(n))
        guess = 4 * mass * length**2 * (freqs[k] / n[k]) ** 2 - (n[k] * math.pi) ** 2 * (EI or 0.0) / length**2
    return float(guess) if guess > 0 and math.isfinite(guess) else float(fallback)


def at_lower_EI(err: BoundError) -> bool:
    """Whether a fit's BoundError is EI at its lower bound (its message names the parameter and the side)."""
    return "EI_ratio = " in str(err) and "is its lower bound" in str(err)
