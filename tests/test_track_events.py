"""track.events on synthetic histories over a wide range of conditions (issue 23, item 6).

Each history is made here in numpy, not by the archive simulator, so that
hundreds run in seconds and the conditions can differ from the simulator's:
the tension follows the cable's temperature (the air's daily cycle and
weather, the cable lagging the air by up to an hour) with a thermal
coefficient of either sign, a daily swing of the tension from 0.1 % to 1 %
of it, a record-to-record scatter from 0.03 % to 0.3 %, records every 10
minutes to every hour, 1 to 7 days.

Before the fix: a 1-day history fitted its level and thermal coefficient on
half a day and reported the other half's misfit as a lasting change (the
issue's +0.37 % on a healthy archive); a 1.5 % loss under a daily swing of
comparable size was placed up to 8 records late and sized −1.3 % or less
(b held from the training window and the followed level took part of it);
17 % of such losses were not found within 3 records.
"""

from __future__ import annotations

import numpy as np
import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.report.track import _normalised_label
from stcs_ident.track.events import (
    MIN_MONITORED,
    MIN_TRAINING,
    MONITORING,
    MONITORING_RULE,
    NOT_ENOUGH_HISTORY,
    TRAINING,
    analyse_history,
    state_note,
)

STEP = -0.015
REFERENCE = 4e5


def _history(rng, *, days, interval, step_at=None, swing=None, scatter=None, lag=None, step=STEP, coefficient=None):
    """Tension (N), air temperature (°C), times (s) of one history; random conditions unless given (a thermal
    ``coefficient`` per °C given sets the swing)."""
    n = int(days * 86400 // interval)
    swing = 10 ** rng.uniform(-3, -2) if swing is None else swing  # half the daily swing of the tension, relative
    amplitude = rng.uniform(2, 10)  # °C, half the daily swing of the air
    coefficient = rng.choice([-1, 1]) * swing / amplitude if coefficient is None else coefficient  # per °C
    scatter = 10 ** rng.uniform(np.log10(3e-4), np.log10(3e-3)) if scatter is None else scatter
    lag = rng.uniform(0, 1) if lag is None else lag  # h, the cable's temperature behind the air's
    start = rng.uniform(0, 24)  # h of the day of the first record
    hours = start + np.arange(n) * interval / 3600
    weather = np.cumsum(rng.standard_normal(n)) * 0.05 * np.sqrt(interval / 600)  # °C, followed by the cable
    air = 12 - amplitude * np.cos(2 * np.pi * (hours - 5) / 24) + weather
    cable = 12 - amplitude * np.cos(2 * np.pi * (hours - 5 - lag) / 24) + weather
    tension = REFERENCE * (1 + coefficient * (cable - 12)) * (1 + scatter * rng.standard_normal(n))
    if step_at is not None:
        tension[step_at:] *= 1 + step
    return tension, air, (hours - start) * 3600.0


def _healthy(n_histories, seed):
    rng = np.random.default_rng(seed)
    reported = []
    for k in range(n_histories):
        days = 1 + k % 7
        interval = rng.choice([600.0, 1200.0, 1800.0, 3600.0])
        tension, air, times = _history(rng, days=days, interval=interval)
        history = analyse_history(tension, air, REFERENCE, times=times)
        assert history.state == (NOT_ENOUGH_HISTORY if days == 1 else MONITORING), (days, history.state)
        reported += [(days, interval, e.index, e.change) for e in history.events]
    return reported


def _steps(n_histories, seed):
    """Per history with a 1.5 % loss: whether it alone was found within 3 records, and (change − STEP) / 1σ."""
    rng = np.random.default_rng(seed)
    found, z = [], []
    for k in range(n_histories):
        days = 2 + k % 6
        interval = rng.choice([600.0, 1200.0, 1800.0, 3600.0])
        per_day = int(86400 // interval)
        at = int(rng.integers(per_day + 3, days * per_day - 3))  # after a day's training, 3 records before the end
        swing = 10 ** (-3 + k / max(n_histories - 1, 1))  # 0.1 % … 1 % of the tension, evenly in log
        tension, air, times = _history(rng, days=days, interval=interval, step_at=at, swing=swing)
        events = analyse_history(tension, air, REFERENCE, times=times).events
        near = [e for e in events if abs(e.index - at) <= 3]
        found.append(len(events) == 1 and len(near) == 1)
        z += [(e.change - STEP) / e.uncertainty for e in near]
    return np.array(found), np.abs(np.array(z))


def test_a_day_of_records_is_not_enough_history_not_a_change():
    """A 1-day history (the issue's healthy archive, and one with a loss at midday) sets its level and its
    thermal coefficient over the whole day: 'not enough history yet', no change, whatever the records."""
    rng = np.random.default_rng(3)
    for interval, step_at in ((600.0, None), (600.0, 72), (3600.0, None), (3600.0, 12)):
        tension, air, times = _history(rng, days=1, interval=interval, step_at=step_at, lag=1.0)
        history = analyse_history(tension, air, REFERENCE, times=times)
        assert history.state == NOT_ENOUGH_HISTORY and history.events == ()
        assert history.monitored_from == tension.size
        assert np.all(np.isfinite(history.normalised)) and np.isfinite(history.thermal_coefficient)
    # without times, the training window is TRAINING records (a day of 10-minute records)
    assert analyse_history(tension[:20], air[:20], REFERENCE).state == NOT_ENOUGH_HISTORY


def test_a_history_shorter_than_a_day_is_not_normalised_by_a_part_of_a_cycle():
    """Temperature terms fitted on two hours of a falling temperature take the records' drift for a thermal
    effect: the temperature terms wait for a whole training window, and until then the normalised tension is the
    identified one (before: b = −0.075 %/°C fitted here on a tension that does not follow the temperature)."""
    rng = np.random.default_rng(11)
    hours = np.arange(12) / 6.0
    air = 10.5 - 1.15 * hours  # °C, the morning of the damped stay's figure: one way only
    tension = REFERENCE * (1 + 0.002 * hours / 2 + 5e-4 * rng.standard_normal(12))  # a slow drift, no thermal term
    history = analyse_history(tension, air, REFERENCE, times=hours * 3600.0)
    assert history.state == NOT_ENOUGH_HISTORY and np.isnan(history.thermal_coefficient)  # not fitted, not 0
    np.testing.assert_allclose(history.normalised, tension, rtol=1e-12)
    # a whole day of the same records' kind: the thermal coefficient is fitted again
    day, day_air, times = _history(np.random.default_rng(12), days=1, interval=600.0, swing=5e-3, scatter=3e-4,
                                   lag=0.0)
    whole = analyse_history(day, day_air, REFERENCE, times=times)
    assert np.isfinite(whole.thermal_coefficient) and whole.thermal_coefficient != 0.0
    # the figure's legend says which (report.track)
    assert _normalised_label(history) == "not normalised yet (less than a day)"
    assert _normalised_label(whole) == f"normalised to {whole.mean_temperature:.1f} °C"


def test_a_step_in_a_history_shorter_than_two_days_is_not_taken_for_a_thermal_effect():
    """Issue 37: a day (or a day and a half) of records with a 2 % step and a daily cycle. One daily cycle
    cannot tell a step from a thermal effect unless the step is in the model: the temperature terms are fitted
    beside a possible step, and b is within 0.05 %/°C of the truth (the issue's bound). Before, fitted with one
    level, b took the step: |b − truth| up to 0.44 %/°C, beyond 0.05 in 138 of 200 such 1-day histories
    (the issue's archive: −0.271 %/°C against −0.05)."""
    rng = np.random.default_rng(37)
    truth = -5e-4  # per °C, the simulator's and the issue's
    for k in range(60):
        days, interval = (1.0, 1.5)[k % 2], (600.0, 1800.0, 3600.0)[k % 3]
        n = int(days * 86400 // interval)
        at = int(rng.integers(MIN_MONITORED, n - MIN_MONITORED))
        step = (-0.02, 0.02)[k % 4 // 2]
        tension, air, times = _history(rng, days=days, interval=interval, step_at=at, step=step, coefficient=truth)
        history = analyse_history(tension, air, REFERENCE, times=times)
        assert abs(history.thermal_coefficient - truth) <= 5e-4, (k, history.thermal_coefficient)  # the issue's
        if days == 1.0:
            assert history.state == NOT_ENOUGH_HISTORY and history.events == ()
    # healthy: b as fitted with one level (no step kept where the records show none)
    tension, air, times = _history(rng, days=1, interval=600.0, swing=5e-3, scatter=3e-4, lag=0.0)
    alone = analyse_history(tension, air, REFERENCE, times=times)
    hours = times / 3600.0
    x = np.column_stack([np.ones(hours.size), air - air.mean(), np.gradient(air, hours)])
    coefficients, *_ = np.linalg.lstsq(x, tension / REFERENCE - 1, rcond=None)
    assert alone.thermal_coefficient == pytest.approx(coefficients[1], rel=1e-9)  # the same least squares


def test_a_history_not_monitoring_yet_says_how_many_records_it_needs():
    """The records still needed before change detection starts: a day of records (by their times; at least
    MIN_TRAINING) and MIN_MONITORED more, counted from the history; projected at the records' interval while
    the first day is not yet covered."""
    rng = np.random.default_rng(5)
    tension, air, times = _history(rng, days=2, interval=3600.0)
    per_day = 24  # hourly records
    for n in (per_day, per_day + 1, per_day + MIN_MONITORED - 1):  # the day covered: exact
        history = analyse_history(tension[:n], air[:n], REFERENCE, times=times[:n])
        assert (history.state, history.records_needed, history.projected) == (
            NOT_ENOUGH_HISTORY, per_day + MIN_MONITORED - n, False)
        assert state_note(history) == (f"not monitoring yet: {MONITORING_RULE}: "
                                       f"{per_day + MIN_MONITORED - n} more record{'s' * (n != per_day + 2)}")
    history = analyse_history(tension[:20], air[:20], REFERENCE, times=times[:20])  # 4 hours of the day to come
    assert (history.records_needed, history.projected) == (per_day + MIN_MONITORED - 20, True)
    assert state_note(history).endswith(f"about {per_day + MIN_MONITORED - 20} more records at the records' interval")
    history = analyse_history(tension[:5], air[:5], REFERENCE, times=times[:5] * 4)  # 4-hourly: 6 a day, 12 needed
    assert history.records_needed == MIN_TRAINING + MIN_MONITORED - 5
    assert analyse_history(tension[:1], air[:1], REFERENCE, times=times[:1]).records_needed is None  # no interval
    assert analyse_history(tension[:20], air[:20], REFERENCE).records_needed == TRAINING + MIN_MONITORED - 20
    monitoring = analyse_history(tension, air, REFERENCE, times=times)
    assert (monitoring.state, monitoring.records_needed, state_note(monitoring)) == (MONITORING, 0, MONITORING)


def test_healthy_one_day_histories_of_ten_minute_records_report_nothing_even_without_times():
    """The issue's case: a day of 10-minute records, the call without times (TRAINING records, a day of them).
    Before, 18 of these 100 histories reported a lasting change (b fitted on half the day)."""
    rng = np.random.default_rng(8)
    for _ in range(100):
        tension, air, _times = _history(rng, days=1, interval=600.0)
        history = analyse_history(tension, air, REFERENCE)
        assert history.events == () and history.state == NOT_ENOUGH_HISTORY


def test_times_as_datetimes_or_seconds_give_the_same_history():
    rng = np.random.default_rng(4)
    tension, air, seconds = _history(rng, days=3, interval=3600.0, step_at=50)
    stamps = np.datetime64("2026-03-01T00:00:00", "ns") + (seconds * 1e9).astype("timedelta64[ns]")
    a = analyse_history(tension, air, REFERENCE, times=seconds)
    b = analyse_history(tension, air, REFERENCE, times=stamps)
    assert [(e.index, e.alarm) for e in a.events] == [(e.index, e.alarm) for e in b.events]
    assert a.monitored_from == b.monitored_from == 24
    # the same numbers but for rounding: the datetimes are whole nanoseconds
    assert np.allclose([(e.change, e.uncertainty) for e in a.events], [(e.change, e.uncertainty) for e in b.events],
                       rtol=1e-9)
    assert len(a.events) == 1 and abs(a.events[0].index - 50) <= 3  # hourly: a day is 24 records, not 144
    with pytest.raises(InputError, match="times"):
        analyse_history(tension, air, REFERENCE, times=seconds[:-1])


def test_the_issues_late_shrunken_loss_is_found_at_its_record_and_sized():
    """Hourly records, a daily swing of the tension half the size of the loss (±0.75 %), 0.1 % scatter, a
    1.5 % loss on day 3: before, found 6 records late and sized −1.24 %; now at its record, within 2σ."""
    rng = np.random.default_rng(23)
    z = []
    for _ in range(20):
        tension, air, times = _history(rng, days=4, interval=3600.0, step_at=60, swing=0.0075, scatter=1e-3, lag=0.0)
        [event] = analyse_history(tension, air, REFERENCE, times=times).events
        assert abs(event.index - 60) <= 1, event  # the CUSUM's own change point was 6 records late
        z.append(abs(event.change - STEP) / event.uncertainty)
    # an honest 1σ: |z| <= 2 in 95 % of histories, 20 histories allow 2 beyond by chance (binomial, p = 0.07)
    assert np.sum(np.array(z) > 2) <= 2 and max(z) <= 4, np.round(z, 2)


def test_healthy_histories_of_one_to_seven_days_report_no_change():
    """210 healthy histories, 30 for each length of 1 to 7 days (the issue's acceptance: none reported)."""
    assert _healthy(210, seed=11) == []


def test_a_loss_under_daily_swings_is_found_within_three_records_and_sized():
    """200 histories with a 1.5 % loss, swings 0.1 % … 1 % (the issue's acceptance): each found, alone, within 3
    records of its start; its size within 2σ in ≥ 92 % and within 3σ in ≥ 98 %. An honest 1σ gives 95.4 % and
    99.7 %; measured over seeds 12-15 with 300 histories each: 93-96 % and 99-100 % (hourly records, whose
    windows of 48 records give the scatter and its correlation less well: 93 %), |z| at most 3.7. 92 % is 2
    binomial σ below 95.4 % for 200 histories."""
    found, z = _steps(200, seed=12)
    assert found.all(), np.flatnonzero(~found)
    assert np.mean(z <= 2) >= 0.92 and np.mean(z <= 3) >= 0.98, (np.mean(z <= 1), np.mean(z <= 2), np.mean(z <= 3))


def test_a_cable_lagging_the_air_is_modelled_not_mistaken_for_a_change():
    """The cable's temperature 2 h behind the air's, a swing of ±1 % and 0.03 % scatter: the lag's misfit
    (±0.5 %) dwarfs the scatter. The lag is fitted (a term in dθ/dt) and a 1.5 % loss is found at its record;
    without the term, the misfit hid it (no event at all in these 5 histories)."""
    rng = np.random.default_rng(6)
    for k in range(10):
        healthy = k % 2 == 0
        tension, air, times = _history(rng, days=4, interval=1800.0, step_at=None if healthy else 130, swing=0.01,
                                       scatter=3e-4, lag=2.0)
        history = analyse_history(tension, air, REFERENCE, times=times)
        assert abs(history.thermal_lag - 2.0) < 0.3, history.thermal_lag  # θ(t − L) ≈ θ − L dθ/dt: first order
        if healthy:
            assert history.events == ()
        else:
            [event] = history.events
            assert abs(event.index - 130) <= 1 and abs(event.change - STEP) <= 4 * event.uncertainty, event
