"""A cable's tension history: normalised for temperature, and its lasting changes found (CUSUM).

Model
    y_i = T_i / T_ref − 1 = μ_j + b (θ_i − θ̄) + c θ̇_i + e_i

    with μ_j the level between two lasting changes, b the relative change
    of tension per °C (a cable's thermal strain against its anchorages),
    θ_i the record's temperature (b = c = 0 when records carry none), θ̇_i
    its rate (°C/h, from the records' times; per record without them) and
    c = −b L for a cable whose own temperature lags the recorded one by L
    (θ(t − L) ≈ θ − L θ̇: the sun heats the air before the steel), e_i the
    record-to-record scatter (traffic and wind: the mean tension over ten
    minutes is not the same twice), the identification's own error and
    what the temperature model still misses (a weather drift the cable does
    not follow: slow, correlated from record to record). The normalised
    tension is T_ref (1 + y_i − b (θ_i − θ̄) − c θ̇_i): what it would have
    been at the mean temperature θ̄.

Detection: Page's two-sided CUSUM (Page 1954; Montgomery, *Introduction to
Statistical Quality Control*, ch. 9) run as a monitor would have run it,
record after record:

1. Training. The records of the first day (``TRAINING_SPAN``, by the
   records' times; without times, the first ``TRAINING`` records, a day of
   10-minute records), and at least ``MIN_TRAINING`` records, give the
   level μ, b and c (least squares over a whole daily cycle) and the
   scatter. A history that does not reach ``MIN_MONITORED`` records past
   its training window has **not enough history yet**
   (:attr:`History.state`): no change is reported, whatever the records
   show, and :attr:`History.records_needed` counts the records still to
   come (the first day's projected at the records' median interval while
   it is not yet covered); :func:`state_note` says so in words, for the
   command's line, the report and the JSON alike. The training window was
   once cut to half the history when the history was short: a 1-day
   archive then fitted b on half a day's cycle and reported its other
   half's misfit as a lasting change (+0.37 %).
2. The residuals are counted in their long-run scatter s √((1 + ρ)/(1 − ρ)):
   s robust (1.4826 × the median absolute residual), ρ the lag-1
   correlation of the training residuals (with its small-sample bias,
   (1 + 3ρ)/n, added back). What the temperature model misses is slow;
   counted against the record-to-record s alone it added up in the sums
   like a change. Each later record's standardised residual z, clipped to
   ±``CLIP`` (a single wild record adds at most CLIP − k: a change must
   last to be seen), feeds S⁺ = max(0, S⁺ + z − k) and
   S⁻ = max(0, S⁻ − z − k); an alarm when either exceeds h. Between alarms
   μ follows the residuals slowly (an exponential average with the
   training window's memory, ``ADAPT``): a slow drift is not a lasting
   change, a step is found within a few records, long before the average
   moves.
3. Where and how large. The CUSUM's own change point (where the alarming
   sum last left zero) is only a start: a step under a daily thermal swing
   of comparable size is seen late, and the level has begun to follow it.
   The change is placed and sized by least squares on the relative
   tensions around it (a day before, a day after, since the last change),
   y = μ + Δ H(i − τ) + b (θ − θ̄) + c θ̇, the temperature terms fitted
   jointly with the step and τ the record that minimises the residual sum
   of squares among those from a day before the alarm to the alarm. Held
   fixed, b would absorb the part of the step that its window's
   temperatures correlate with, and the followed level would take some
   more: a 1.5 % loss under a thermal swing half its size was found 6
   records late and sized −1.24 %. The 1σ of Δ is the regression's, from
   the robust scatter of its residuals (× n / (n − p) for the p fitted
   terms), times (1 + ρ)/(1 − ρ) in variance for residuals correlated from
   record to record. An alarm whose step is less than ``CONFIRM`` σ is no
   change (a slow misfit the sums caught): the sums restart from zero at
   the level of the last day's records. Else the change is Δ / (1 + μ)
   (after / before − 1) and the monitor restarts at the new level after a
   new training window.

Then b and c are fitted again on the whole history with one level per
segment between the changes found, and the detection is run once more
with them (a day's cycle alone fits them less well than weeks of them).

A history shorter than two training windows has one daily cycle to fit b
and c on, and a step of tension within it correlates with the cycle (up
to 0.9 for a step where the temperature crosses its mean): fitted with
one level, b takes the step for a thermal effect (a 1-day archive with a
2 % step: −0.25 %/°C fitted against −0.05). Its temperature terms are so
fitted beside a possible step: y = μ + Δ H(i − τ) + b (θ − θ̄) + c θ̇ on
its first segment (the whole history while not monitoring yet; before the
first change found, else), τ the best of the records with
``MIN_MONITORED`` or more on either side, the step kept when it is
``CONFIRM`` σ or more (as an alarm's), else one level. Not monitoring
yet, the step is not reported (its level stays one) but the scatter s is
counted around it. A history shorter than its training window (less than
a day) has no temperature terms: b = c = 0, the tension as identified.
On 200 synthetic 1-day histories with a 2 % step (``tests/test_track_events.py``'s
conditions) |b − truth| is at most 0.044 %/°C (0.44 with one level); on
healthy ones b is as with one level (the largest error 0.026 %/°C against
0.022). A step inside the training window moves the monitor's b and
level at any length (the monitor assumes its training window holds no
change); under two windows the b reported is fitted beside it.

Choice of k and h: k = 1 (a change of 2 s is detected fastest) and h = 8.
For independent Gaussian residuals the average run between false alarms
(Siegmund's approximation, two-sided) is then beyond 10⁷ records; the
residuals of a real history are neither, which is why h is high: the
false-alarm rate on healthy simulated histories with daily cycles and
scatter is measured in ``benchmarks/track.py`` and in
``tests/test_track_events.py``. With CLIP = 4, a change of 5 long-run s
or more raises the alarm after 3 records.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import InputError

__all__ = ["CLIP", "MIN_MONITORED", "MIN_TRAINING", "MONITORING_RULE", "NOT_ENOUGH_HISTORY", "THRESHOLD", "TRAINING",
           "TRAINING_SPAN", "Event", "History", "analyse_history", "analyse_series", "records_needed", "state_note"]

TRAINING = 144  # records that set a level when the records carry no times: a day of 10-minute records
TRAINING_SPAN = 86400.0  # s: with times, the records of the first day set the level (a whole daily cycle)
SLACK = 1.0  # k, in units of the scatter
THRESHOLD = 8.0  # h, in units of the scatter
CLIP = 4.0  # standardised residuals are clipped to ± this before the sums
MIN_TRAINING = 12  # fewer records than this cannot set a level
MIN_MONITORED = 3  # records after the training window before a change can be seen (one must last 3 records)
CONFIRM = 4.0  # an alarm is a change only if the step fitted around it is this many of its 1σ
ADAPT = 1.0  # the monitored level follows the residuals with this weight per training window of records
MONITORING = "monitoring"
NOT_ENOUGH_HISTORY = "not enough history yet"


@dataclass(frozen=True)
class Event:
    """A lasting change of tension: where it started, its relative size (after / before − 1) and 1σ."""

    index: int  # first record after the change, in the history's order
    change: float
    uncertainty: float
    alarm: int  # the record at which the CUSUM raised the alarm


@dataclass(frozen=True)
class History:
    """A cable's analysed history: per record the normalised tension, and the events.

    ``state`` is ``"monitoring"`` once the history reaches ``MIN_MONITORED``
    records past its training window (``monitored_from``, the first record
    a change could be seen at), else ``"not enough history yet"`` (no event
    can be reported; ``monitored_from`` is then the history's length, and
    ``records_needed`` the records still to come before detection starts).
    :func:`state_note` says it in words.
    """

    normalised: np.ndarray  # N, at the mean temperature
    level: np.ndarray  # relative level μ of each record's segment
    thermal_coefficient: float  # b, per °C (0 without temperatures; NaN before a whole day: not fitted yet)
    mean_temperature: float
    scatter: float  # s, relative
    events: tuple[Event, ...]
    state: str = MONITORING
    monitored_from: int = 0
    # L, h (records when the history has no times): the cable's temperature behind the records'; 0 without
    # temperatures, and meaningless where b is (no thermal effect to lag)
    thermal_lag: float = 0.0
    # records still to come before change detection starts (0 once monitoring; None: not known, fewer than two
    # records give no interval to count a day in); :func:`records_needed`
    records_needed: int | None = 0
    # whether that count is projected at the records' interval (the first day not yet covered) or exact
    projected: bool = False


def analyse_history(tension: np.ndarray, temperature: np.ndarray, reference: float, *,
                    training: int = TRAINING, times: np.ndarray | None = None) -> History:
    """Normalise a cable's tension history (records in time order) and find its lasting changes.

    Parameters
    ----------
    tension, temperature : ndarray (N,)
        Per record, in time order; temperatures NaN (or constant) when the
        records carry none.
    reference : float
        The reference tension T_ref (N).
    training : int
        Records that set a level when ``times`` is not given.
    times : ndarray (N,), optional
        The records' start times, seconds from any origin or datetime64:
        the training window is then the first day of records
        (``TRAINING_SPAN``), whatever the interval between records.

    Returns
    -------
    History
        See the module docstring for the method.
    """
    y = np.asarray(tension, dtype=float) / reference - 1.0
    r, levels, beta, mean_theta, scatter, events, state, monitored = analyse_series(
        y, temperature, training=training, times=times)
    b, lag = _coefficients(beta)
    return History(reference * (1 + r), levels, b, mean_theta, scatter, events, state, monitored, lag,
                   *records_needed(y.size, times, training=training))


def records_needed(n: int, times: np.ndarray | None = None, *, training: int = TRAINING) -> tuple[int | None, bool]:
    """The records still to come before change detection starts on a history of ``n`` records (0 once it has),
    and whether the count is projected.

    Detection starts once the history reaches ``MIN_MONITORED`` records past its training window: the records
    of the first day by their ``times`` (at least ``MIN_TRAINING``), or ``training`` records without times.
    While the first day is not yet covered, the records it will hold are projected at the records' median
    interval (``projected`` True); with fewer than two timed records there is no interval: (None, True).
    """
    seconds = _seconds(times, n)
    window = _training_length(seconds, training)
    projected = False
    if seconds is not None and not _whole_cycle(seconds, n, training):
        if n < 2 or not np.median(np.diff(seconds)) > 0:
            return None, True
        step = float(np.median(np.diff(seconds)))
        later = max(int(np.ceil((TRAINING_SPAN - 0.5 - seconds[-1]) / step)) - 1, 0)  # ½ s: rounding
        window = max(MIN_TRAINING, int(np.sum(seconds < TRAINING_SPAN - 0.5)) + later)
        projected = True
    return max(window + MIN_MONITORED - n, 0), projected and window + MIN_MONITORED > n


#: When change detection starts, in words (:func:`state_note`).
MONITORING_RULE = (f"change detection starts after a day of records (at least {MIN_TRAINING}) and {MIN_MONITORED} "
                   "more")


def state_note(history: History) -> str:
    """The history's state in words: ``monitoring``, or that it is not monitoring yet, the rule and the
    records still needed (``not monitoring yet: change detection starts after a day of records and 3 more:
    3 more records``). The command's line, the report and the JSON say this."""
    if history.state == MONITORING:
        return MONITORING
    needed = history.records_needed
    if needed is None:  # fewer than two records: no interval to count a day in
        return f"not monitoring yet: {MONITORING_RULE}"
    count = f"{'about ' if history.projected else ''}{needed} more record{'s' if needed != 1 else ''}"
    return f"not monitoring yet: {MONITORING_RULE}: {count}" + (" at the records' interval" if history.projected
                                                               else "")


def analyse_series(y: np.ndarray, temperature: np.ndarray, *, training: int = TRAINING,
                   times: np.ndarray | None = None, weights: np.ndarray | None = None,
                   logarithmic: bool = False):
    """The method of the module docstring on any series y_i = μ_j + b (θ_i − θ̄) + c θ̇_i + w_i e_i.

    ``weights`` w_i (default 1) scale each record's error: residuals are
    counted in units of s w_i in the sums, the fits are weighted by 1/w_i²
    (:mod:`.damper_history` passes the per-record 1σ of the damper's
    coefficient). An event's size is Δ / (1 + μ) (y a relative change), or
    e^Δ − 1 when ``logarithmic`` (y the logarithm of a damper's
    coefficient), its 1σ to first order. With ``logarithmic`` the step's 1σ
    takes the larger of the robust scatter and the standard deviation of
    the weighted residuals: a coefficient's per-record 1σ is itself uncertain,
    its weighted residuals a heavy-tailed mixture whose median absolute
    residual understates their spread (on synthetic histories, a 30 % loss
    sized within its 1σ / 2σ in 64 / 93 % of 200 cases with the robust
    scatter alone, 67 / 94 % with the larger).

    Returns
    -------
    (r, levels, beta, mean_theta, scatter, events, state, monitored_from) : r = y − x β (the series at the
    mean temperature), each record's level, the temperature coefficients, θ̄ (NaN without temperatures), the
    robust scatter s of the weighted residuals, the events, :attr:`History.state` and
    :attr:`History.monitored_from`.
    """
    y = np.asarray(y, dtype=float)
    theta = np.asarray(temperature, dtype=float)
    w = np.ones(y.size) if weights is None else np.asarray(weights, dtype=float)
    if w.size != y.size or not np.all(np.isfinite(w) & (w > 0)):
        raise InputError(f"must be {y.size} positive finite values", field="weights")
    seconds = _seconds(times, y.size)
    use_temperature = theta.size > 0 and np.all(np.isfinite(theta)) and np.ptp(theta) > 0
    mean_theta = float(np.mean(theta)) if use_temperature else float("nan")
    x = _thermal_terms(theta - mean_theta, seconds) if use_temperature else np.zeros((y.size, 0))
    training = _training_length(seconds, training)
    if y.size < training + MIN_MONITORED:
        # The temperature terms only from a whole training window (a daily cycle): fitted on a part of one, where
        # the temperature runs one way, they take the part's drift and scatter for a thermal effect (11 records of
        # a damped stay over 2 h, 10.5 → 8.2 °C: every coefficient 97–153 kN s/m 'normalised' to 66–104).
        whole = _whole_cycle(seconds, y.size, training) and y.size > x.shape[1] + 1
        # A whole cycle: the terms fitted beside a step the records may show (not reported: not monitoring yet).
        segments = np.zeros(y.size, dtype=int)
        if whole:
            segments = _possible_step(y, x, segments, w, logarithmic)
        beta = _thermal(y, x, segments, w) if whole else np.zeros(x.shape[1])
        r = y - x @ beta
        level = np.median(r) if weights is None else _weighted_mean(r, w)
        levels = np.full(y.size, level) if y.size else y
        fitted = np.array([_weighted_mean(r[segments == j], w[segments == j])
                           for j in range(int(segments.max()) + 1)])[segments] if y.size else y
        # s around the levels fitted (a step included): the record-to-record scatter, not half the step. Terms
        # not fitted (less than a whole cycle) are NaN, not 0: a coefficient of 0 would read as a measured one.
        return (r, levels, beta if whole else np.full(x.shape[1], np.nan), mean_theta, _scale((r - fitted) / w), (),
                NOT_ENOUGH_HISTORY, int(y.size))
    beta = _thermal(y[:training], x[:training], np.zeros(training, dtype=int), w[:training])
    events = _detect(y, x, beta, training, w, logarithmic)
    if use_temperature:  # b again, from the whole history with a level per segment
        segments = _segments(y.size, events)
        if y.size < 2 * training:  # one daily cycle to tell b from a step its training window may hold
            segments = _possible_step(y, x, segments, w, logarithmic)
        beta = _thermal(y, x, segments, w)
        events = _detect(y, x, beta, training, w, logarithmic)
    segments = _segments(y.size, events)
    r = y - x @ beta
    levels = np.array([_weighted_mean(r[segments == j], w[segments == j])
                       for j in range(len(events) + 1)])[segments]
    return r, levels, beta, mean_theta, _scale((r - levels) / w), tuple(events), MONITORING, int(training)


def _weighted_mean(r: np.ndarray, w: np.ndarray) -> float:
    return float(np.sum(r / w**2) / np.sum(1 / w**2)) if r.size else float("nan")


def _seconds(times, n: int) -> np.ndarray | None:
    """The records' times in seconds from the first, or None (not given, or not all finite)."""
    if times is None:
        return None
    t = np.asarray(times)
    if np.issubdtype(t.dtype, np.datetime64):
        t = (t - t[0]) / np.timedelta64(1, "s") if t.size else t.astype(float)
    t = np.asarray(t, dtype=float)
    if t.size != n:
        raise InputError(f"has {t.size} values for {n} tensions", field="times")
    return t - t[0] if n and np.all(np.isfinite(t)) else None


def _training_length(seconds: np.ndarray | None, training: int) -> int:
    """Records in the training window: the first day's by their times if known, else ``training``."""
    if seconds is not None:
        return max(MIN_TRAINING, int(np.sum(seconds < TRAINING_SPAN - 0.5)))  # ½ s: rounding
    return max(MIN_TRAINING, int(training))


def _whole_cycle(seconds: np.ndarray | None, n: int, training: int) -> bool:
    """Whether the history covers its whole training window: a day by its times (the last record's interval
    included), else ``training`` records."""
    if seconds is not None and n > 1:
        return float(seconds[-1] + np.median(np.diff(seconds))) >= TRAINING_SPAN - 0.5  # ½ s: rounding
    return n >= training


def _thermal_terms(x: np.ndarray, seconds: np.ndarray | None) -> np.ndarray:
    """The temperature regressors: θ − θ̄ and its rate dθ/dt (°C/h; per record without usable times)."""
    hours = seconds / 3600.0 if seconds is not None and np.all(np.diff(seconds) > 0) else np.arange(x.size, dtype=float)
    rate = np.gradient(x, hours) if x.size > 1 else np.zeros_like(x)
    return np.column_stack([x, rate])


def _coefficients(beta: np.ndarray) -> tuple[float, float]:
    """b (per °C) and the lag of the cable's temperature behind the records' (h, from y ≈ b θ(t − L))."""
    if beta.size == 0:
        return 0.0, 0.0
    b = float(beta[0])
    return b, float(-beta[1] / b) if b != 0 else 0.0


def _detect(y: np.ndarray, x: np.ndarray, beta: np.ndarray, training: int, w: np.ndarray,
            logarithmic: bool = False) -> list[Event]:
    """The sequential CUSUM of the module docstring, the temperature terms ``beta`` held while monitoring,
    each residual counted in units of the scatter times its weight ``w``."""
    r = y - x @ beta
    events: list[Event] = []
    start = 0  # first record of the current level's training window
    adapt = ADAPT / training
    while start + training < r.size:
        base = r[start:start + training]
        level = np.median(base)
        scale = _scale((base - level) / w[start:start + training]) * np.sqrt(
            _correlation_factor((base - np.mean(base)) / w[start:start + training]))
        up = down = 0.0
        last_zero_up = last_zero_down = start + training
        event = None
        for i in range(start + training, r.size):
            z = np.clip((r[i] - level) / (scale * w[i]), -CLIP, CLIP)
            up, down = max(0.0, up + z - SLACK), max(0.0, down - z - SLACK)
            if up == 0.0:
                last_zero_up = i + 1
            if down == 0.0:
                last_zero_down = i + 1
            if up > THRESHOLD or down > THRESHOLD:
                guess = last_zero_up if up > THRESHOLD else last_zero_down
                event = _fit_step(y, x, events[-1].index if events else 0, guess, i, training, start + training,
                                  w, logarithmic)
                if abs(event.change) >= CONFIRM * event.uncertainty:
                    break
                # not a step: what the temperature model misses, slow and correlated; the level catches up
                event, up, down = None, 0.0, 0.0
                last_zero_up = last_zero_down = i + 1
                level = np.median(r[max(start, i + 1 - training):i + 1])
                continue
            level += adapt * np.clip(r[i] - level, -CLIP * scale * w[i], CLIP * scale * w[i])  # a slow drift
        if event is None:
            break
        events.append(event)
        start = event.index
    return events


def _fit_step(y: np.ndarray, x: np.ndarray, first: int, guess: int, alarm: int, training: int,
              earliest: int, w: np.ndarray, logarithmic: bool = False) -> Event:
    """The change's record and size: least squares of y = μ + Δ H(i − τ) + b x around it (b fitted jointly,
    each record weighted by 1/w²), τ among the records from a day before the alarm (not before ``earliest``)
    to the alarm."""
    lo = max(first, guess - training)
    hi = min(y.size, max(guess, alarm) + training)
    candidates = range(max(earliest, alarm - training + 1, lo + 2), alarm + 1)
    best = None
    ww = w[lo:hi, None]
    yw = y[lo:hi] / ww[:, 0]
    for tau in candidates:
        design = _step_design(x[lo:hi], tau - lo) / ww
        coefficients, *_ = np.linalg.lstsq(design, yw, rcond=None)
        rss = float(np.sum((yw - design @ coefficients) ** 2))
        if best is None or rss < best[0]:
            best = (rss, tau, coefficients, design)
    _, tau, coefficients, design = best
    residuals = yw - design @ coefficients
    covariance = np.linalg.pinv(design.T @ design)
    dof = residuals.size / max(residuals.size - design.shape[1], 1)  # residuals are smaller than the errors
    spread = max(_scale(residuals), float(np.std(residuals))) if logarithmic else _scale(residuals)
    variance = spread ** 2 * dof * covariance[1, 1] * _correlation_factor(residuals)
    mu, delta, sigma = float(coefficients[0]), float(coefficients[1]), float(np.sqrt(variance))
    if logarithmic:  # y = ln(value): after / before − 1 = e^Δ − 1
        return Event(int(tau), float(np.expm1(delta)), float(np.exp(delta)) * sigma, int(alarm))
    return Event(int(tau), delta / (1 + mu), sigma / (1 + mu), int(alarm))


def _possible_step(y: np.ndarray, x: np.ndarray, segment: np.ndarray, w: np.ndarray,
                   logarithmic: bool = False) -> np.ndarray:
    """``segment`` with one more step in its first segment where the records show one: the step of least
    squares y = μ + Δ H(i − τ) + x β fitted there (τ with at least ``MIN_MONITORED`` records on either side),
    kept when its size is ``CONFIRM`` σ or more (as an alarm's). The temperature terms of a history shorter
    than two training windows are fitted beside it: on one daily cycle they would take a step for a thermal
    effect."""
    end = int(np.argmax(segment > 0)) if segment.size and segment.max() > 0 else segment.size
    if x.shape[1] == 0 or end < 2 * MIN_MONITORED + x.shape[1] + 2:  # no step to tell from the terms
        return segment
    step = _fit_step(y[:end], x[:end], 0, 0, end - MIN_MONITORED, end, MIN_MONITORED, w[:end], logarithmic)
    if not abs(step.change) >= CONFIRM * step.uncertainty:
        return segment
    return segment + (np.arange(segment.size) >= step.index)


def _step_design(x: np.ndarray, at: int) -> np.ndarray:
    n = x.shape[0]
    return np.column_stack([np.ones(n), (np.arange(n) >= at).astype(float), x])


def _correlation_factor(residuals: np.ndarray) -> float:
    """(1 + ρ)/(1 − ρ), ρ the lag-1 correlation of ``residuals`` (0 … 0.95): the variance of a mean of
    residuals correlated from record to record as AR(1), relative to independent ones."""
    r = residuals - np.mean(residuals) if residuals.size else residuals
    rho = float(np.sum(r[1:] * r[:-1]) / np.sum(r * r)) if r.size > 2 and np.any(r) else 0.0
    rho = min(max(rho + (1 + 3 * rho) / max(r.size, 1), 0.0), 0.95)  # + its bias over n records (Kendall 1954)
    return (1 + rho) / (1 - rho)


def _segments(n: int, events: list[Event]) -> np.ndarray:
    segment = np.zeros(n, dtype=int)
    for e in events:
        segment[e.index:] += 1
    return segment


def _thermal(y: np.ndarray, x: np.ndarray, segment: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The coefficients of the temperature terms ``x`` (N, p) in y = μ_segment + x β, least squares weighted
    by 1/w²."""
    if x.shape[1] == 0:
        return np.zeros(0)
    levels = [(segment == j).astype(float) for j in range(int(segment.max()) + 1)]
    coefficients, *_ = np.linalg.lstsq(np.column_stack([x, *levels]) / w[:, None], y / w, rcond=None)
    return coefficients[:x.shape[1]]


def _scale(residuals: np.ndarray) -> float:
    """Robust standard deviation: 1.4826 × the median absolute residual (never zero)."""
    if residuals.size == 0:
        return float("nan")
    mad = 1.4826 * float(np.median(np.abs(residuals - np.median(residuals))))
    return max(mad, 1e-12)
