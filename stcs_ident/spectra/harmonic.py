"""The harmonic series of a set of peaks, found from the peaks alone: no nominal tension needed.

A cable's modes form a series f_n = n f₀ √(1 + B n²): a taut string (B = 0)
stretched by its bending stiffness (B = π² EI / (T L²) for pinned ends, the
tensioned-beam closed form of docs/model.md; clamped ends and sag move the
lowest modes by a few per cent, which the tolerance below absorbs). Given
only the peak frequencies, :func:`harmonic_series` finds the series (f₀, B)
and the mode number of each peak: the order-preserving assignment of least
cost (the numbering's dynamic programme, :func:`.numbering.assign`), with a
cost per family mode skipped inside the assigned span so that a sub-harmonic
series (f₀/2 numbering every peak with an even number) never ties with the
true one. Candidates start from each of the lowest peaks taken as mode
1, 2, … and are refined by weighted least squares of (f/n)² = f₀² + f₀² B n²
(linear in f₀² and f₀² B).

Uses: the plausibility of a campaign on the record path (is the nominal model's
scale that of the peaks? a unit or sampling-rate slip shows as a ratio far from
1, before the nominal numbering bends the numbers to it), and the quick tension
from one record (``tension --record``), which numbers the peaks this way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .numbering import assign

__all__ = ["HarmonicSeries", "harmonic_series"]

#: Relative misfit allowed per mode (clamped ends and sag move the lowest modes of a stay by up to a few per cent
#: from the pinned beam-string form; attachments move single modes by as much).
TOLERANCE = 0.02
#: ... and at most this share of the peaks' median spacing (a tolerance of 2 % at mode 30 would be 60 % of the
#: spacing, and a sub-harmonic series would absorb any stray peak). The same for every candidate: a tolerance
#: scaled by each candidate's own spacing gave a series twice as wide a tolerance twice as loose, and a sagging
#: 198 m stay's peaks went to it.
SPACING_SHARE = 0.1
#: The refinement's first tolerance, as a share of the spacing (:func:`_refine`).
LOOSE_SHARE = 0.3
#: Cost of a peak left out of the series (a squared standardised residual: beyond 3σ).
UNASSIGNED_COST = 9.0
#: Cost of a mode of the series skipped between the lowest and the highest assigned mode (a sub-harmonic series,
#: f₀/2 numbering every peak 2n, skips one mode per peak: it must cost more than the true series, even where
#: two stray peaks happen to fall on its odd modes).
SKIP_COST = 2.0
#: Another series whose fundamental differs by more than this (relative) and whose cost is within
#: :data:`AMBIGUITY` of the best makes the series ambiguous.
DISTINCT = 0.05
AMBIGUITY = 2.0
#: Highest mode number considered (a lowest peak above mode 150 of a cable is not a cable's series).
MAX_MODE = 150
#: The peaks numbered, the lowest (enough to judge a scale and to number the modes a tension needs; the dynamic
#: programme's cost grows with the peaks times the modes: 38 peaks of a 120 m stay cost 0.23 s, 20 cost 0.03 s).
MAX_PEAKS = 20
#: Largest B considered: ξ = √(T L² / EI) ≥ 2 (the stiffest members a tension is measured on).
MAX_INHARMONICITY = math.pi**2 / 4


@dataclass(frozen=True)
class HarmonicSeries:
    """The series f_n = n f₀ √(1 + B n²) that the peaks form.

    Attributes
    ----------
    fundamental : float
        f₀, Hz: the series' scale (the taut-string fundamental of a pinned cable; with clamped ends it carries
        their few per cent).
    inharmonicity : float
        B (0 for a taut string).
    modes : ndarray of int
        Per peak, in the order given: its mode number in the series (0: left out).
    cost : float
        The assignment's cost (squared standardised residuals, left-out peaks and skipped modes).
    ambiguous : bool
        Another series with a fundamental more than 5 % away fits almost as well (one peak, or peaks that
        several spacings explain): its numbers are not to be trusted.
    alternative : float or None
        The fundamental of the best such other series, Hz.
    """

    fundamental: float
    inharmonicity: float
    modes: np.ndarray
    cost: float
    ambiguous: bool
    alternative: float | None = None

    def frequency(self, modes) -> np.ndarray:
        """The series' frequencies of ``modes`` (Hz)."""
        n = np.asarray(modes, float)
        return n * self.fundamental * np.sqrt(1.0 + self.inharmonicity * n**2)

    @property
    def n_assigned(self) -> int:
        """How many peaks the series numbers."""
        return int(np.count_nonzero(self.modes))


def harmonic_series(frequencies, uncertainties=None, *, tolerance: float = TOLERANCE,
                    max_peaks: int = MAX_PEAKS) -> HarmonicSeries | None:
    """The harmonic series of the peaks ``frequencies`` (Hz; 1σ ``uncertainties``, default none beyond the
    tolerance): module docstring. Only the lowest ``max_peaks`` peaks are numbered (the others get mode 0).
    None with no peak; one peak is mode 1 of an ambiguous series."""
    f = np.asarray(frequencies, float).ravel()
    u = np.zeros_like(f) if uncertainties is None else np.asarray(uncertainties, float).ravel()
    if f.shape != u.shape:
        raise ValueError("frequencies and uncertainties must have the same length")
    keep = np.isfinite(f) & (f > 0) & np.isfinite(u)
    if not keep.any():
        return None
    order = np.flatnonzero(keep)[np.argsort(f[keep])][:max_peaks]
    fs, us = f[order], u[order]
    sigma = (us, tolerance)
    modes = np.zeros(f.size, int)
    if fs.size == 1:
        modes[order] = 1
        return HarmonicSeries(float(fs[0]), 0.0, modes, 0.0, True, float(fs[0]) / 2)
    scored = _score_starts(fs, sigma, _starts(fs))
    stretched = _stretched(scored[:STRETCHED])
    if stretched.size:
        best_per_f0: dict = {}
        for row in scored + _score_starts(fs, sigma, stretched):  # each fundamental with its best stretch
            if row[1] not in best_per_f0 or row[0] < best_per_f0[row[1]][0]:
                best_per_f0[row[1]] = row
        scored = sorted(best_per_f0.values(), key=lambda row: row[0])
    starts = np.array([(row[1], row[2]) for row in scored[:REFINED]])
    refined = sorted(_refine_all(fs, sigma, starts[:, 0], starts[:, 1]), key=lambda s: s[0])
    cost, f0, b, assigned = refined[0]
    rivals = [r for r in refined[1:] if abs(r[1] / f0 - 1) > DISTINCT]
    ambiguous = bool(rivals) and rivals[0][0] - cost <= AMBIGUITY or np.count_nonzero(assigned) < 2
    modes[order] = assigned
    return HarmonicSeries(float(f0), float(b), modes, float(cost), bool(ambiguous),
                          float(rivals[0][1]) if rivals else None)


def _score_starts(fs, sigma, starts: np.ndarray) -> list:
    """A quick cost of every start (rows f₀, B) at once, best first: each peak taken as its nearest mode of the
    series (closed form), a peak beyond :data:`UNASSIGNED_COST` or on a mode taken already left out, the
    skipped modes counted. It only ranks the starts; the refinement assigns by the dynamic programme."""
    f0, b = starts[:, :1], starts[:, 1:]
    sigma = _sigma(fs, sigma, starts[:, 0])
    x = fs[None, :] / f0
    with np.errstate(invalid="ignore", divide="ignore"):
        n_cont = np.where(b > 0, np.sqrt((np.sqrt(1 + 4 * b * x**2) - 1) / (2 * np.where(b > 0, b, 1))), x)
    n = np.maximum(np.rint(n_cont), 1)
    residual = ((fs[None, :] - n * f0 * np.sqrt(1 + b * n**2)) / sigma) ** 2
    on = residual < UNASSIGNED_COST
    on[:, 1:] &= n[:, 1:] != n[:, :-1]  # sorted peaks: a repeated mode is taken by its first peak only
    total = np.where(on, residual, UNASSIGNED_COST).sum(axis=1) + SKIP_COST * _skipped(np.where(on, n, 0))
    order = np.argsort(total, kind="stable")
    return [(float(total[k]), float(starts[k, 0]), float(starts[k, 1]), None) for k in order]


#: The best starts refined (:func:`_refine_all`).
REFINED = 24
#: The best starts are tried with every stretch of :data:`STRETCHES` too (a taut-string start's high modes are
#: off a stretched series by more than the tolerance, and the low modes alone never show the stretch).
STRETCHED = 20
STRETCHES = np.geomspace(1e-6, MAX_INHARMONICITY, 48)


def _stretched(rows) -> np.ndarray:
    """Rows (f₀, B) of each of ``rows``' fundamentals with every stretch of :data:`STRETCHES`."""
    f0 = np.unique([row[1] for row in rows])
    return np.column_stack([np.repeat(f0, STRETCHES.size), np.tile(STRETCHES, f0.size)]) if f0.size else np.zeros((0, 2))


def _starts(fs: np.ndarray) -> np.ndarray:
    """Rows (f₀, B): taut-string series with each of the three lowest peaks as mode 1, 2, …, :data:`MAX_MODE`
    (deduplicated) and the spacing of neighbouring peaks as f₀ (a series whose low modes were not picked);
    stretched series through two neighbouring low peaks taken as modes n and n + 1 (a stiff member's high modes),
    and through two of the three lowest peaks taken as low modes (a stiff member's)."""
    candidates = []
    for peak in fs[:3]:
        candidates.extend(peak / np.arange(1, MAX_MODE + 1))
    gaps = np.diff(fs)
    candidates.extend(gaps[gaps > 0])
    values = np.sort(np.asarray(candidates))
    values = values[values >= fs[-1] / (2 * MAX_MODE)]
    kept = [values[0]]
    for v in values[1:]:
        if v > kept[-1] * 1.002:
            kept.append(v)
    rows = [(v, 0.0) for v in kept]
    for i in range(min(2, fs.size - 1)):  # neighbouring peaks as neighbouring modes n, n + 1 of a stretched series
        n = np.arange(1, MAX_MODE + 1, dtype=float)
        yi, yj = (fs[i] / n) ** 2, (fs[i + 1] / (n + 1)) ** 2
        c = (yj - yi) / (2 * n + 1)
        a = yi - c * n**2
        ok = (a > 0) & (c > 0) & (c <= MAX_INHARMONICITY * np.where(a > 0, a, 1))
        rows.extend(zip(np.sqrt(a[ok]), c[ok] / a[ok]))
    low = fs[:3]
    for i in range(low.size):
        for j in range(i + 1, low.size):
            for ni in range(1, 9):
                for nj in range(ni + 1, ni + 9):
                    yi, yj = (low[i] / ni) ** 2, (low[j] / nj) ** 2
                    c = (yj - yi) / (nj**2 - ni**2)
                    a = yi - c * ni**2
                    if a > 0 and 0 < c / a <= MAX_INHARMONICITY:
                        rows.append((math.sqrt(a), c / a))
    return np.asarray(rows)


def _sigma(fs, sigma, f0, share: float | None = None) -> np.ndarray:
    """Each peak's σ: its own 1σ and the model tolerance, at most ``share`` (default :data:`SPACING_SHARE`) of the
    peaks' own median spacing. The same for every candidate series (``f0`` only shapes the result: one row per
    series), so that a series twice as wide is not judged by a tolerance twice as loose. ``sigma``: (the peaks'
    1σ, the tolerance)."""
    u, tolerance = sigma
    f0 = np.asarray(f0, float)
    share = SPACING_SHARE if share is None else share
    spacing = float(np.median(np.diff(fs))) if fs.size > 1 else float(fs[0])
    model = np.minimum(tolerance * fs, share * spacing)
    out = np.sqrt(u**2 + model**2)
    return np.broadcast_to(out, (*f0.shape, fs.size)) if f0.ndim else out


def _scores(fs, sigma, f0: np.ndarray, b: np.ndarray, share: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(cost with the skips, modes) of each series (f₀, B) at once (one dynamic programme over the families,
    padded with infinity), its tolerance at most ``share`` of the peaks' spacing (default :data:`SPACING_SHARE`)."""
    top = fs[-1] * (1 + 4 * TOLERANCE)
    count = np.minimum(4 * MAX_MODE, (top / f0).astype(int) + 3)
    n = np.arange(1, count.max() + 1, dtype=float)
    families = np.where(n[None, :] <= count[:, None], n[None, :] * f0[:, None] * np.sqrt(1 + b[:, None] * n**2),
                        np.inf)
    modes, cost = assign(fs, _sigma(fs, sigma, np.float64(1.0), share), families, UNASSIGNED_COST)
    return cost + SKIP_COST * _skipped(modes), modes


def _skipped(modes: np.ndarray) -> np.ndarray:
    """Per row of mode numbers (0: a peak left out), the modes of the series skipped between its lowest and its
    highest assigned one."""
    on = modes > 0
    lowest = np.where(on, modes, np.inf).min(axis=1)
    highest = np.where(on, modes, -np.inf).max(axis=1)
    return np.where(on.any(axis=1), highest - lowest + 1 - on.sum(axis=1), 0)


def _refine_all(fs, sigma, f0: np.ndarray, b: np.ndarray, iterations: int = 6) -> list:
    """Each start (f₀, B) assigned by the dynamic programme, then weighted least squares of (f/n)² = a + c n² on
    its assigned peaks (a = f₀², c = f₀² B), re-assigned, until the numbers stand (all starts in step, one
    programme per step): first with a tolerance of :data:`LOOSE_SHARE` of the spacing (a taut-string start
    leaves a stretched series' high modes out at the strict tolerance, and the low modes alone never show the
    stretch: a 198 m stay's modes 17-37, 1.4 % above the string at ξ 545, were left to the series f₀ × 2), then
    at the strict one. Per start, its best series at the strict tolerance: (cost, f₀, B, modes)."""
    f0, b = f0.astype(float).copy(), b.astype(float).copy()
    cost, modes = _scores(fs, sigma, f0, b)
    best = [(float(cost[k]), float(f0[k]), float(b[k]), modes[k]) for k in range(f0.size)]
    for share in (LOOSE_SHARE, SPACING_SHARE):
        current = _scores(fs, sigma, f0, b, share)[1]
        active = np.ones(f0.size, bool)
        for _ in range(iterations):
            for k in np.flatnonzero(active):
                fit = _fit(fs, sigma, current[k], f0[k])
                if fit is None:
                    active[k] = False
                else:
                    f0[k], b[k] = fit
            if not active.any():
                break
            cost, strict = _scores(fs, sigma, f0, b)
            again = strict if share == SPACING_SHARE else _scores(fs, sigma, f0, b, share)[1]
            for k in np.flatnonzero(active):
                if cost[k] < best[k][0]:
                    best[k] = (float(cost[k]), float(f0[k]), float(b[k]), strict[k])
                if np.array_equal(again[k], current[k]):
                    active[k] = False
            current = again
            if not active.any():
                break
    return best


def _fit(fs, sigma, modes, f0) -> tuple[float, float] | None:
    """(f₀, B) of the weighted least squares of (f/n)² = a + c n² on the assigned peaks (B = 0 where c < 0 or
    the peaks hold fewer than three modes); None with fewer than two assigned."""
    on = modes > 0
    if np.count_nonzero(on) < 2:
        return None
    n = modes[on].astype(float)
    y = (fs[on] / n) ** 2
    w = n**2 / (2 * fs[on] * _sigma(fs, sigma, np.array(f0))[on])  # 1 / σ of y
    a, c = np.linalg.lstsq(np.column_stack([np.ones_like(n), n**2]) * w[:, None], y * w, rcond=None)[0]
    if c < 0 or np.unique(n).size <= 2:
        a, c = float(np.sum(w**2 * y) / np.sum(w**2)), 0.0
    if not a > 0:
        return None
    return math.sqrt(a), min(c / a, MAX_INHARMONICITY)
