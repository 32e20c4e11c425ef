"""Synthetic histories of a damper's coefficient, as ``track`` fits it per record, without simulating records.

Used by ``tests/test_track_dampers.py`` and ``benchmarks/track.py --damper-false-alarms``.

The damper's oil follows the air with a lag (its temperature θ_d(t) = θ(t − lag), the daily cycle and the
weather's drift; ``unfollowed`` leaves a share of the drift out, a misfit of the temperature model), the
coefficient is c_ref e^{a (θ_d − 12 °C)} with a = −1.5 % per °C (a silicone oil thins as
it warms), times (1 − loss) from the record ``at`` on. Each record's relative 1σ is log-normal: median
``sigma`` and log-spread ``spread``; its error is Gaussian in ln c with a true scale that differs from the
reported 1σ by a log-normal factor of spread 0.2 (a fit's 1σ is itself uncertain).

Measured per-record 1σ of the coefficient (``track.process.process_record``, the 120 m stay of the
benchmark with a 100 kN s/m damper 3 m from A, ζ1 ≈ 1 %, three sensors, wind 20 N/m rms, 100 Hz, 30 dB):
600 s records 7.3–13.6 % (21 seeds, median 8.4 %, log-spread 0.15; the truth within 1σ in 14, 2σ in 20
of them); 60 s records 16 %–4.3× (nine seeds with a
coefficient, median 40 %, log-spread 1.0). The wind of a real archive varies from record to record, which
the simulator's constant pressure does not: the default spread (0.5) is wider than the 600 s records'.
"""

from __future__ import annotations

import numpy as np

#: Median relative 1σ of a 10-minute record's coefficient (measured: 8.4 %, 7.3–13.6 %).
SIGMA = 0.09
#: Log-spread of the relative 1σ from record to record.
SPREAD = 0.5
#: Relative change of the coefficient per °C.
THERMAL = -0.015
REFERENCE = 1.0e5  # N s/m


def coefficient_history(rng: np.random.Generator, *, days: float = 30.0, loss: float = 0.0, at: int | None = None,
                        sigma: float = SIGMA, spread: float = SPREAD, lag: float = 1.0, drift: float = 0.05,
                        unfollowed: float = 0.0):
    """(coefficient, its 1σ, air temperature, times in s) of 10-minute records over ``days`` (see the module);
    ``unfollowed``: the share of the air's weather drift the damper's oil does not follow (a sensor in the
    sun, say)."""
    hours = np.arange(round(days * 144)) / 6.0
    weather = np.cumsum(rng.standard_normal(hours.size)) * drift
    cycle = 12 - 6 * np.cos(2 * np.pi * (hours - 5) / 24)
    air = cycle + weather
    steps = round(lag * 6)  # the oil lags the air by ``lag`` hours, its weather too
    lagged = np.concatenate([np.full(steps, weather[0]), weather[:weather.size - steps]])
    oil = 12 - 6 * np.cos(2 * np.pi * (hours - 5 - lag) / 24) + (1 - unfollowed) * lagged
    true = REFERENCE * np.exp(THERMAL * (oil - 12))
    if loss:
        true = np.where(np.arange(hours.size) >= at, true * (1 - loss), true)
    relative = sigma * np.exp(spread * rng.standard_normal(hours.size))
    error = relative * np.exp(0.2 * rng.standard_normal(hours.size))
    measured = true * np.exp(error * rng.standard_normal(hours.size))
    return measured, measured * relative, air, hours * 3600.0
