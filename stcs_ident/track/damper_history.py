"""A damper's history: its coefficient normalised for temperature, and its lasting changes found (CUSUM).

Model
    y_i = ln(c_i / c_ref) = μ_j + b (θ_i − θ̄) + c θ̇_i + w_i e_i

    with c_i the coefficient fitted on record i (jointly with the tension,
    :mod:`.process`), c_ref the damper's recorded coefficient, μ_j the level
    between two lasting changes and b the relative change of the
    coefficient per °C: a viscous damper's oil thickens in the cold
    (silicone oils lose 1–2 % of their viscosity per °C), so ln c is
    linear in the temperature over a season's range, as the tension's
    relative change is; c θ̇ lets the damper's temperature lag the
    recorded one, as the cable's does. The normalised coefficient is
    c_ref exp(y_i − b (θ_i − θ̄) − c θ̇_i): what it would have been at the
    mean temperature θ̄.

Weights. A coefficient is seen through the damping ratios it adds, and a
ratio's 1σ from one record depends on how much that record's wind excited
each mode: the per-record 1σ of ln c (σ_c / c) varies by a factor of three
or more from record to record (the tension's by far less), so the scatter
of ln c is not one number. Each record's error is w_i e_i with
w_i = max(σ_i, σ̃ / 2) / σ̃, σ_i = σ_c,i / c_i and σ̃ their median over
the history: the CUSUM counts each residual in units of s w_i and the
level, the temperature terms and a change's step are fitted by least
squares weighted by 1/w_i². A record with a broad 1σ then moves the sums
little, a sharp one more; the floor at half the median keeps a record
whose 1σ came out too small from counting for more than four typical ones.
Unweighted, the records with the broadest 1σ set the robust scatter s and
the sums lose the sharp records' evidence: on synthetic histories with the
1σ spread e^±1 (``benchmarks/track.py --damper-false-alarms`` runs both), a
30 % loss was found within a day in 89 of 100 (weighted: 100) and 6 false
events came in 100 healthy cable-months (weighted: none); with 60-s records
(1σ 40 %), 23 found of 100 (weighted: 53), 26 false events (none).

Detection is the tension's (:mod:`.events`: training on the first day,
Page's two-sided CUSUM with the same k, h, clip and confirmation, the
change placed and sized by a step fitted jointly with the temperature
terms). A change's size is after / before − 1 = e^Δ − 1, its 1σ
e^Δ σ_Δ.

What it sees: a lasting change of the damper's coefficient as the
frequencies and damping ratios see it (a leak, a seizure that stops the
dashpot working, a bolt loose at the clamp: each lowers or raises the
damping the modes get). What it does not see: which of these it is (a
seized damper's coefficient rises, then the model of a dashpot no longer
fits), a change of the damper's spring or mass (held at the campaign's
values), or a slow loss over weeks (the monitored level follows drifts
slower than its training window, as the tension's does).
"""

from __future__ import annotations

import numpy as np

from ..core.errors import InputError
from .events import TRAINING, History, analyse_series, records_needed

__all__ = ["SIGMA_FLOOR", "analyse_coefficient", "coefficient_weights"]

#: A record's weight never exceeds that of a 1σ this fraction of the history's median 1σ.
SIGMA_FLOOR = 0.5


def coefficient_weights(coefficient: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """w_i = max(σ_i, SIGMA_FLOOR σ̃) / σ̃ with σ_i the relative 1σ of each record's coefficient."""
    relative = np.asarray(sigma, dtype=float) / np.asarray(coefficient, dtype=float)
    if relative.size == 0:
        return relative
    typical = float(np.median(relative))
    return np.maximum(relative, SIGMA_FLOOR * typical) / typical


def analyse_coefficient(coefficient: np.ndarray, sigma: np.ndarray | None, temperature: np.ndarray,
                        reference: float, *, training: int = TRAINING, times: np.ndarray | None = None,
                        weighted: bool = True) -> History:
    """Normalise a damper's coefficient history (records in time order) and find its lasting changes.

    Parameters
    ----------
    coefficient, sigma : ndarray (N,)
        Per record, the fitted coefficient (N s/m, > 0) and its 1σ (> 0;
        None or ``weighted=False``: every record weighs the same).
    temperature : ndarray (N,)
        Per record (NaN when the records carry none).
    reference : float
        The damper's recorded coefficient c_ref (N s/m).
    training, times :
        As :func:`~stcs_ident.track.events.analyse_history`.

    Returns
    -------
    History
        ``normalised``: the coefficient at the mean temperature (N s/m);
        ``level``: the level between changes relative to c_ref (the
        coefficient's level is c_ref (1 + level)); ``thermal_coefficient``:
        b, the relative change of the coefficient per °C; ``scatter``: s,
        of ln c, in units of the median relative 1σ when weighted; the
        events' ``change`` after / before − 1.
    """
    c = np.asarray(coefficient, dtype=float)
    if not np.all(np.isfinite(c) & (c > 0)) or not reference > 0:
        raise InputError("must be positive and finite (a damper's coefficient, N s/m)", field="coefficient")
    weights = None
    if weighted and sigma is not None:
        s = np.asarray(sigma, dtype=float)
        if s.size != c.size or not np.all(np.isfinite(s) & (s > 0)):
            raise InputError(f"must be {c.size} positive finite values", field="coefficient_sigma")
        weights = coefficient_weights(c, s)
    r, levels, beta, mean_theta, scatter, events, state, monitored = analyse_series(
        np.log(c / reference), temperature, training=training, times=times, weights=weights, logarithmic=True)
    b = float(beta[0]) if beta.size else 0.0
    lag = float(-beta[1] / b) if beta.size and b != 0 else 0.0  # (NaN with b not fitted yet)
    return History(reference * np.exp(r), np.expm1(levels), b, mean_theta, scatter, events, state, monitored, lag,
                   *records_needed(c.size, times, training=training))
