"""A cable's tension history: normalised for temperature, and its lasting changes found (CUSUM).

Model
    y_i = T_i / T_ref − 1 = μ_j + b (θ_i − θ̄) + e_i

    with μ_j the level between two lasting changes, b the relative change
    of tension per °C (a cable's thermal strain against its anchorages),
    θ_i the record's temperature (b = 0 when records carry none) and e_i
    the record-to-record scatter (traffic and wind: the mean tension over
    ten minutes is not the same twice) plus the identification's own error.
    The normalised tension is T_ref (1 + y_i − b (θ_i − θ̄)): what it would
    have been at the mean temperature θ̄.

Detection: Page's two-sided CUSUM (Page 1954; Montgomery, *Introduction to
Statistical Quality Control*, ch. 9) run as a monitor would have run it,
record after record:

1. The first ``TRAINING`` records (a day of 10-minute records) give the
   level μ, the thermal coefficient b (least squares) and the scatter s
   (1.4826 × the median absolute residual: robust to an outlier).
2. Each later record's standardised residual z = (y − μ − b (θ − θ̄)) / s,
   clipped to ±``CLIP`` (a single wild record adds at most CLIP − k: a
   change must last to be seen), feeds S⁺ = max(0, S⁺ + z − k) and
   S⁻ = max(0, S⁻ − z − k); an alarm when either exceeds h. Between
   alarms μ follows the residuals slowly (an exponential average with a
   day's memory, ``ADAPT``): a slow drift (a season, a temperature the
   linear model does not follow) is not a lasting change, a step is
   found within a few records, long before the average moves.
3. The change started where the alarming sum last left zero (the maximum
   likelihood change point of a step under the CUSUM). Its size is the
   difference of the levels before (since the last change) and after (the
   next ``TRAINING`` records, or all that remain), relative to the level
   before, with 1σ √(s_b² f_b / n_b + s_a² f_a / n_a): each window's
   robust scatter, its size, and f = (1 + ρ)/(1 − ρ) for residuals
   correlated from record to record (ρ their lag-1 correlation); the
   monitor restarts at the new level after those records.

Then b is fitted again on the whole history with one level per segment
between the changes found, and the detection is run once more with it
(a day's cycle alone fits b less well than weeks of them).

Choice of k and h: k = 1 (a change of 2 s is detected fastest) and h = 8.
For independent Gaussian residuals the average run between false alarms
(Siegmund's approximation, two-sided) is then beyond 10⁷ records; the
residuals of a real history are neither (a thermal lag the linear model
misses, weather), which is why h is high: the false-alarm rate on healthy
simulated histories with daily cycles and scatter is measured in
``benchmarks/track.py``. With CLIP = 4, a change of 5 s or more is found
after 3 records.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["CLIP", "THRESHOLD", "TRAINING", "Event", "History", "analyse_history"]

TRAINING = 144  # records that set a level: a day of 10-minute records
SLACK = 1.0  # k, in units of the scatter
THRESHOLD = 8.0  # h, in units of the scatter
CLIP = 4.0  # standardised residuals are clipped to ± this before the sums
MIN_TRAINING = 12  # fewer records than this cannot set a level
ADAPT = 1.0 / TRAINING  # the monitored level follows the residuals with this weight per record


@dataclass(frozen=True)
class Event:
    """A lasting change of tension: where it started, its relative size (after / before − 1) and 1σ."""

    index: int  # first record after the change, in the history's order
    change: float
    uncertainty: float
    alarm: int  # the record at which the CUSUM raised the alarm


@dataclass(frozen=True)
class History:
    """A cable's analysed history: per record the normalised tension, and the events."""

    normalised: np.ndarray  # N, at the mean temperature
    level: np.ndarray  # relative level μ of each record's segment
    thermal_coefficient: float  # b, per °C (0 without temperatures)
    mean_temperature: float
    scatter: float  # s, relative
    events: tuple[Event, ...]


def analyse_history(tension: np.ndarray, temperature: np.ndarray, reference: float, *,
                    training: int = TRAINING) -> History:
    """Normalise a cable's tension history (records in time order) and find its lasting changes."""
    tension = np.asarray(tension, dtype=float)
    theta = np.asarray(temperature, dtype=float)
    use_temperature = theta.size > 0 and np.all(np.isfinite(theta)) and np.ptp(theta) > 0
    mean_theta = float(np.mean(theta)) if use_temperature else float("nan")
    x = theta - mean_theta if use_temperature else np.zeros_like(tension)
    y = tension / reference - 1.0
    training = max(MIN_TRAINING, min(training, y.size // 2))
    if y.size < 2 * MIN_TRAINING:
        b = _thermal(y, x, np.zeros(y.size, dtype=int)) if use_temperature else 0.0
        levels = np.full(y.size, np.median(y - b * x)) if y.size else y
        return History(reference * (1 + y - b * x), levels, b, mean_theta, _scale(y - b * x - levels), ())
    b = _thermal(y[:training], x[:training], np.zeros(training, dtype=int)) if use_temperature else 0.0
    events = _detect(y, x, b, training)
    if use_temperature:  # b again, from the whole history with a level per segment
        b = _thermal(y, x, _segments(y.size, events))
        events = _detect(y, x, b, training)
    segments = _segments(y.size, events)
    levels = np.array([np.mean((y - b * x)[segments == j]) for j in range(len(events) + 1)])[segments]
    return History(reference * (1 + y - b * x), levels, float(b), mean_theta, _scale(y - b * x - levels),
                   tuple(events))


def _detect(y: np.ndarray, x: np.ndarray, b: float, training: int) -> list[Event]:
    """The sequential CUSUM of the module docstring, with the thermal coefficient ``b`` held."""
    r = y - b * x
    events: list[Event] = []
    start = 0  # first record of the current level's training window
    while start + training < r.size:
        base = r[start:start + training]
        level = np.median(base)
        scale = _scale(base - level)
        up = down = 0.0
        last_zero_up = last_zero_down = start + training
        alarm = None
        for i in range(start + training, r.size):
            z = np.clip((r[i] - level) / scale, -CLIP, CLIP)
            up, down = max(0.0, up + z - SLACK), max(0.0, down - z - SLACK)
            if up == 0.0:
                last_zero_up = i + 1
            if down == 0.0:
                last_zero_down = i + 1
            if up > THRESHOLD or down > THRESHOLD:
                alarm = i
                break
            level += ADAPT * np.clip(r[i] - level, -CLIP * scale, CLIP * scale)  # follows a slow drift
        if alarm is None:
            break
        change_at = last_zero_up if up > THRESHOLD else last_zero_down
        before = r[max(events[-1].index if events else 0, change_at - training):change_at]
        after = r[change_at:change_at + training]
        mean_before, mean_after = float(np.mean(before)), float(np.mean(after))
        uncertainty = np.sqrt(_mean_variance(before) + _mean_variance(after)) / (1 + mean_before)
        events.append(Event(int(change_at), (1 + mean_after) / (1 + mean_before) - 1, float(uncertainty),
                            int(alarm)))
        start = change_at
    return events


def _mean_variance(values: np.ndarray) -> float:
    """Variance of the mean of ``values``, residuals correlated from record to record as AR(1): s²/n ×
    (1 + ρ) / (1 − ρ), s robust and ρ the lag-1 correlation (0 … 0.95). Without the factor, the 1σ of a
    change was a third too small under a slow drift the temperature model does not follow."""
    r = values - np.mean(values)
    rho = float(np.sum(r[1:] * r[:-1]) / np.sum(r * r)) if values.size > 2 and np.any(r) else 0.0
    rho = min(max(rho, 0.0), 0.95)
    return _scale(r) ** 2 / values.size * (1 + rho) / (1 - rho)


def _segments(n: int, events: list[Event]) -> np.ndarray:
    segment = np.zeros(n, dtype=int)
    for e in events:
        segment[e.index:] += 1
    return segment


def _thermal(y: np.ndarray, x: np.ndarray, segment: np.ndarray) -> float:
    """b of y = μ_segment + b x, least squares."""
    columns = [x] + [(segment == j).astype(float) for j in range(int(segment.max()) + 1)]
    coefficients, *_ = np.linalg.lstsq(np.column_stack(columns), y, rcond=None)
    return float(coefficients[0])


def _scale(residuals: np.ndarray) -> float:
    """Robust standard deviation: 1.4826 × the median absolute residual (never zero)."""
    if residuals.size == 0:
        return float("nan")
    mad = 1.4826 * float(np.median(np.abs(residuals - np.median(residuals))))
    return max(mad, 1e-12)
