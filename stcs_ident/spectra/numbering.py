"""Mode numbers for picked peaks, from the family structure of the cable.

Nearest-prediction numbering fails as soon as the nominal model is a few
per cent off or a mode is missing: the k-th peak is then taken for mode
k ± 1. Here the whole family is matched instead. The exact model is
evaluated on a grid of tension and bending-stiffness ratios (the batch
solver makes this cheap), so every candidate family keeps the cable's own
pattern (near-harmonic spacing, the bending stiffness's stretch, the
shifts of symmetric modes by attachments and sag). For each family the
peaks get the order-preserving assignment of least cost (dynamic
programming; a peak may stay unassigned at a fixed cost, for spurious or
out-of-plane peaks), with residuals scaled by the measurement uncertainty
plus a model tolerance. The best family gives the numbers; a peak whose
number differs in any family almost as good (within ``ambiguity`` in
cost) is flagged doubtful — never silently guessed. The tolerances, costs
and ranges are :class:`.options.NumberingOptions`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from ..core.errors import InputError, NumberingWarning
from ..core.memo import BoundedCache, model_key
from ..core.model import Attachment, Cable, has_dampers
from ..forward import batch_frequencies
from ..forward.damped import batch_complex_modes
from .options import NumberingOptions


@dataclass(frozen=True)
class Numbering:
    """Mode numbers of a set of peaks.

    Attributes
    ----------
    modes : ndarray of int (n_peaks,)
        Mode number per peak, 0 where the peak is left unassigned.
    doubtful : ndarray of bool (n_peaks,)
        True where an almost equally good family numbers the peak otherwise.
    tension_ratio, EI_ratio : float
        The family that fits best (ratios to the nominal values).
    predicted : ndarray (n_peaks,)
        That family's frequency for each assigned peak (NaN if unassigned).
    cost : float
        Its cost; ``alternatives`` holds (cost, modes) of the runners-up.
    """

    modes: np.ndarray
    doubtful: np.ndarray
    tension_ratio: float
    EI_ratio: float
    predicted: np.ndarray
    cost: float
    alternatives: tuple


def assign(frequencies, sigma, families, unassigned_cost: float = NumberingOptions.unassigned_cost):
    """Order-preserving assignment of peaks to families (dynamic programming,
    vectorised over the families).

    Parameters
    ----------
    frequencies, sigma : arrays (n_peaks,), ascending frequencies
    families : array (n_families, n_modes), ascending predicted frequencies
    unassigned_cost : cost of leaving a peak unassigned (squared standardised residuals)

    Returns
    -------
    modes : int array (n_families, n_peaks), 1-based, 0 = unassigned
    cost : array (n_families,)
    """
    families = np.atleast_2d(families)
    F, K = families.shape
    n = len(frequencies)
    resid = ((frequencies[None, :, None] - families[:, None, :]) / sigma[None, :, None]) ** 2  # (F, n, K)
    # best[:, j, k]: least cost of the first j peaks using the first k modes
    best = np.full((F, n + 1, K + 1), np.inf)
    best[:, 0, :] = 0.0
    choice = np.zeros((F, n + 1, K + 1), dtype=np.int8)  # 0 skip mode, 1 match, 2 peak unassigned
    for j in range(1, n + 1):
        # Row j at once: the match or unassigned option per mode k (ties to the match), then the skip option
        # (best[j, k-1], ties to it) is a running minimum along k, as the recurrence taken mode by mode.
        match = best[:, j - 1, :-1] + resid[:, j - 1, :]
        unassigned = best[:, j - 1, :] + unassigned_cost
        options = unassigned.copy()
        options[:, 1:] = np.minimum(match, unassigned[:, 1:])
        row_choice = np.full((F, K + 1), 2, dtype=np.int8)
        row_choice[:, 1:] = np.where(match <= unassigned[:, 1:], 1, 2)
        running = np.minimum.accumulate(options, axis=1)
        skip = np.zeros((F, K + 1), dtype=bool)
        skip[:, 1:] = running[:, :-1] <= options[:, 1:]
        best[:, j, :] = running
        choice[:, j, :] = np.where(skip, 0, row_choice)
    modes = np.zeros((F, n), dtype=int)
    for fam in range(F):
        j, k = n, K
        ch = choice[fam]
        while j > 0:
            c = ch[j, k]
            if c == 0:
                k -= 1
            elif c == 1:
                modes[fam, j - 1] = k
                j -= 1
                k -= 1
            else:
                j -= 1
    return modes, best[:, n, K]


def number_modes(frequencies: Sequence[float], uncertainties: Sequence[float], cable: Cable,
                 attachments: Sequence[Attachment], tension: float, *, options: NumberingOptions | None = None,
                 tension_model: str = "uniform", plane: str = "in") -> Numbering:
    """Number the peaks by matching the whole family of the cable model.

    Parameters
    ----------
    frequencies, uncertainties : peak frequencies and 1σ uncertainties, Hz
    cable, attachments, tension : the nominal model of the test
    options : NumberingOptions, optional
        Default: the calibrated values. ``model_tolerance`` is the relative
        misfit the model is allowed per mode after tension and EI are
        fitted (attachments, sag, end conditions). Peaks left unassigned
        are retried with ``relaxed_tolerance`` times it; the relaxed
        numbers are kept only if they keep every strict number not flagged
        doubtful and none of the added peaks is doubtful.
        ``tension_range`` and ``EI_range`` are the ratios to nominal
        searched; another family within ``ambiguity`` in cost counts as
        equally good; a peak left unassigned costs ``unassigned_cost``.
    tension_model : the forward model's tension model
    plane : "in" (default) or "out"
        Number against that plane's family (:func:`~stcs_ident.core.planes.plane_view`: out-of-plane, no
        sag-extensibility, springs at ``stiffness_out``, dampers at sin² of their angle).
    """
    options = NumberingOptions() if options is None else options
    f = np.asarray(frequencies, float)
    u = np.asarray(uncertainties, float)
    if f.ndim != 1 or f.shape != u.shape:
        raise InputError("frequencies and uncertainties must be 1-D of equal length", field="frequencies")
    if f.size == 0:
        return Numbering(np.zeros(0, int), np.zeros(0, bool), 1.0, 1.0, np.zeros(0), 0.0, ())
    order = np.argsort(f)
    f, u = f[order], u[order]
    tension_model = (tension_model, {"plane": plane})
    grid = _grid(f, cable, attachments, tension, options, tension_model)
    modes, doubtful, cost, tr, er, family, alternatives = _number(
        f, u, cable, attachments, tension, options.model_tolerance, options, tension_model, grid)
    if np.any(modes == 0):
        # A hidden effect (an unrecorded mass, a moved attachment) can shift single modes by a few per
        # cent, beyond the model tolerance, and the strict pass leaves them unassigned. A relaxed pass
        # may add them, provided it keeps every sure strict number and is unambiguous about the added ones.
        relaxed = _number(f, u, cable, attachments, tension, options.relaxed_tolerance * options.model_tolerance,
                          options, tension_model, grid)
        r_modes, r_doubtful = relaxed[0], relaxed[1]
        added = (modes == 0) & (r_modes > 0)
        sure = (modes > 0) & ~doubtful
        if (added.any() and np.all(r_modes[modes > 0] > 0) and np.array_equal(r_modes[sure], modes[sure])
                and not np.any(r_doubtful[added])):
            modes, doubtful, cost, tr, er, family, alternatives = relaxed
    predicted = np.where(modes > 0, family[np.maximum(modes, 1) - 1], np.nan)
    inverse = np.argsort(order)
    result = Numbering(modes[inverse], doubtful[inverse], float(tr), float(er),
                       predicted[inverse], cost, tuple((c, m[inverse]) for c, m in alternatives))
    if doubtful.any():
        warnings.warn(
            f"mode numbers of the peaks at {', '.join(f'{x:.3f}' for x in f[doubtful])} Hz are doubtful: "
            "another family of modes fits almost as well", NumberingWarning, stacklevel=2)
    return result


def _grid(f, cable, attachments, tension, options: NumberingOptions, tension_model):
    """The search grid: tension ratios, EI ratios, and the families on it, (n_t, n_EI, n_modes) (the strict and
    the relaxed pass share it: only their tolerance differs)."""
    t_ratio = np.geomspace(*options.tension_range, _grid_points(options.tension_range, TENSION_STEP))
    ei_ratio = (np.geomspace(*options.EI_range, _grid_points(options.EI_range, EI_STEP)) if cable.EI > 0
                else np.array([1.0]))
    n_modes = _modes_needed(f, cable, attachments, tension, options.tension_range[0], tension_model)
    key = model_key(cable, tuple(attachments), float(tension), t_ratio.tobytes(), ei_ratio.tobytes(), n_modes,
                    tension_model[0], tuple(sorted(tension_model[1].items())))
    fam = _FAMILIES.get(key)
    if fam is None:
        fam = _families(cable, attachments, tension, t_ratio, ei_ratio, n_modes, tension_model)
        fam.flags.writeable = False
        _FAMILIES.put(key, fam)
    return t_ratio, ei_ratio, fam


#: The search grids' families solved in this process, by model and grid: a monitoring archive numbers every
#: record of a cable against the same nominal model, whose grid is then solved once per worker (the same
#: arrays, so the same numbers, in whatever order or batch the records come). At most this many kept.
MAX_GRIDS = 16
_FAMILIES = BoundedCache(MAX_GRIDS)


#: With a dashpot, the exact (complex) families are solved on a coarser grid of this many tension and EI ratios
#: spanning the search grid (:func:`_families`).
DAMPED_GRID = (3, 4)


def _families(cable, attachments, tension, t_ratio, ei_ratio, n_modes, tension_model) -> np.ndarray:
    """The families on the grid, (n_t, n_EI, n_modes).

    With a dashpot every family is a complex eigenproblem, followed root by root as the dashpots grow (about
    a hundred times an undamped solve), and the grid's 49 × 15 of them made the numbering of a damped stay
    cost 15–20 s. The damper's effect on each frequency is smooth in the tension and EI ratios (its
    parameter η = c π x_d / (l √(H m)) goes as 1/√H; EI moves the mode's slope at the damper slowly), so:
    the families without the dashpots (their springs and masses kept) on the whole grid, times the damped
    to undamped ratio of each mode solved exactly on :data:`DAMPED_GRID` points and interpolated (cubic
    splines of its logarithm). Measured on a 49 × 15 grid of 25 modes, a damper at 2.5 % and 2 % of a 120 m and a
    200 m stay (η₁ 0.3, 1, 5): within 3.2e-4 of the exact families with 3 tension and 4 EI points (1.3e-4 from
    η₁ = 1 on; 1.2e-4 on the 200 m stay). 4 tension points gave the same worst case (3.2e-4; 2e-5 on the 200 m
    stay) for a fifth more time; 7 the same; 3 EI points 8e-4. All well inside the numbering's model tolerance
    (0.3 %). The family finally reported for each candidate is the exact
    one at its fitted ratios (:func:`_family`).
    """
    def solve(t, e, **extra):
        return batch_frequencies(cable, attachments, tension * t[:, None], n_modes, EI=cable.EI * e[None, :],
                                 tension_model=tension_model[0], **tension_model[1], **extra)

    coarse = [min(n, r.size) for n, r in zip(DAMPED_GRID, (t_ratio, ei_ratio))]
    if not has_dampers(attachments) or t_ratio.size * ei_ratio.size <= np.prod(coarse):
        return solve(t_ratio, ei_ratio)
    off = {"coefficients": np.zeros(len(attachments))}
    t_c, e_c = (np.geomspace(r[0], r[-1], n) for n, r in zip(coarse, (t_ratio, ei_ratio)))
    with np.errstate(divide="ignore", invalid="ignore"):
        log_ratio = np.log(solve(t_c, e_c) / solve(t_c, e_c, **off))
    if not np.all(np.isfinite(log_ratio)):
        return solve(t_ratio, ei_ratio)
    log_ratio = make_interp_spline(np.log(t_c), log_ratio, k=min(3, t_c.size - 1), axis=0)(np.log(t_ratio))
    if e_c.size > 1:
        log_ratio = make_interp_spline(np.log(e_c), log_ratio, k=min(3, e_c.size - 1), axis=1)(np.log(ei_ratio))
    return solve(t_ratio, ei_ratio, **off) * np.exp(log_ratio)


def _number(f, u, cable, attachments, tension, model_tolerance, options: NumberingOptions, tension_model, grid):
    """One numbering pass over sorted peaks with a model tolerance: (modes, doubtful, cost, tension ratio,
    EI ratio, family, alternatives). ``tension_model`` here and below: (the tension model, the plane keyword
    of batch_frequencies)."""
    tension_range, EI_range, cost_unassigned = options.tension_range, options.EI_range, options.unassigned_cost
    sigma = np.sqrt(u**2 + (model_tolerance * f) ** 2)
    t_ratio, ei_ratio, fam = grid
    n_modes = fam.shape[-1]
    flat = fam.reshape(-1, n_modes)
    all_modes, all_cost = assign(f, sigma, flat, cost_unassigned)
    # candidate numberings from the best grid families, each refined by a
    # continuous fit of (tension, EI) and re-assigned until stable
    candidates = {}
    for q in np.argsort(all_cost)[:40]:
        key = tuple(all_modes[q])
        if key not in candidates and len(candidates) < 8:
            i, j = np.unravel_index(q, fam.shape[:2])
            candidates[key] = (t_ratio[i], ei_ratio[j])
    refined = {}
    surface = _FamilySurface(np.log(t_ratio), np.log(ei_ratio), fam)
    for key, (t0, r0) in candidates.items():
        modes, cost, tr, er, family = _refine(f, sigma, np.array(key), t0, r0, surface, cable, attachments, tension,
                                              tension_model, n_modes, tension_range, EI_range, cost_unassigned)
        if tuple(modes) not in refined or refined[tuple(modes)][0] > cost:
            refined[tuple(modes)] = (cost, tr, er, family)
    ranked = sorted(refined.items(), key=lambda kv: kv[1][0])
    modes = np.array(ranked[0][0])
    cost, tr, er, family = ranked[0][1]
    doubtful = np.zeros(f.size, bool)
    alternatives = []
    for m, (c, *_rest) in ranked[1:]:
        if c - cost <= options.ambiguity:
            doubtful |= np.array(m) != modes
            alternatives.append((c, np.array(m)))
    return modes, doubtful, cost, tr, er, family, alternatives


#: The search grid's steps, those of 49 x 15 families over the default ranges (0.6-1.5 in tension: 1.9 %, about
#: 1 % in frequency, a third of a mode's spacing at mode 30, so neighbouring numberings are both on the grid;
#: 0.2-5 in EI: 26 %). A narrower range (the second plane's search near the first's fit) gets as many points
#: as its span needs at these steps.
TENSION_STEP, EI_STEP = 2.5 ** (1 / 48), 25 ** (1 / 14)


def _grid_points(bounds, step: float) -> int:
    """Points of a geometric grid over ``bounds`` at most ``step`` apart (as a ratio), at least 5 (the cubic
    splines of the refinement need 4)."""
    return max(5, math.ceil(math.log(bounds[1] / bounds[0]) / math.log(step) - 1e-6) + 1)


def _refine(f, sigma, modes, t0, r0, surface, cable, attachments, tension, tension_model, n_modes, tension_range,
            EI_range, unassigned_cost):
    """Fit (tension, EI) ratios to the assigned peaks (within the searched ranges), re-assign, repeat. The fit
    runs on ``surface``, the families of the grid interpolated (:class:`_FamilySurface`); the family returned,
    its cost and the final assignment are the exact model's at the fitted ratios."""
    fit_ei = cable.EI > 0
    x = np.log([t0, r0] if fit_ei else [t0])
    lower = np.log([tension_range[0], EI_range[0]][: x.size])
    upper = np.log([tension_range[1], EI_range[1]][: x.size])
    for _ in range(3):
        assigned = modes > 0
        if assigned.sum() >= (2 if fit_ei else 1):
            idx = modes[assigned] - 1

            def residual(x, idx=idx, assigned=assigned):
                return (f[assigned] - surface(x)[idx]) / sigma[assigned]

            def jacobian(x, idx=idx, assigned=assigned):
                return -surface.gradient(x)[idx] / sigma[assigned, None]

            x = _fit_ratios(residual, jacobian, np.clip(x, lower, upper), lower, upper)
        new_modes, _ = assign(f, sigma, surface(x)[None, :], unassigned_cost)
        if np.array_equal(new_modes[0], modes):
            break
        modes = new_modes[0]
    family = _family(x, cable, attachments, tension, tension_model, n_modes)
    new_modes, cost = assign(f, sigma, family[None, :], unassigned_cost)
    modes = new_modes[0]
    ratios = np.exp(x)
    return modes, float(cost[0]), float(ratios[0]), float(ratios[1]) if fit_ei else 1.0, family


def _fit_ratios(residual, jacobian, x, lower, upper, iterations: int = 50) -> np.ndarray:
    """Least squares of the log ratios (one or two) within their bounds: Levenberg–Marquardt steps projected
    onto the bounds. Two unknowns on a smooth surface: a few steps converge where scipy's least_squares spent
    most of the numbering's time in its own bookkeeping."""
    r = residual(x)
    cost = r @ r
    damping = 1e-3
    for _ in range(iterations):
        J = jacobian(x)
        normal = J.T @ J
        gradient = J.T @ r
        scale = np.maximum(normal.diagonal(), _TINY_CURVATURE)
        # A ratio held at its bound by the descent direction stays there; the others take the reduced step.
        free = ~(((x <= lower) & (gradient > 0)) | ((x >= upper) & (gradient < 0)))
        step = np.zeros_like(x)
        if not free.any():
            break
        sub = np.ix_(free, free)
        try:
            step[free] = -np.linalg.solve(normal[sub] + damping * np.diag(scale[free]), gradient[free])
        except np.linalg.LinAlgError:
            break
        trial = np.clip(x + step, lower, upper)
        if np.max(np.abs(trial - x)) < 1e-10:  # of a log ratio (1e-10 relative), or held at a bound
            break
        r_trial = residual(trial)
        cost_trial = r_trial @ r_trial
        if cost_trial < cost:
            gain = cost - cost_trial
            x, r, cost, damping = trial, r_trial, cost_trial, max(damping / 3, 1e-9)
            if gain <= 1e-12 * cost:
                break
        else:
            damping *= 4
            if damping > 1e8:
                break
    return x


#: A curvature floor for the damping of a direction the peaks do not constrain (EI from modes of a string).
_TINY_CURVATURE = 1e-12


class _FamilySurface:
    """The families of the search grid as smooth functions of the log ratios (bicubic splines per mode, or a
    cubic spline in the tension for a string), with their gradient: the refinement's model.

    The grid steps are 1.9 % in tension and 26 % in EI, on which the frequencies are smooth (∝ √tension,
    and EI's stretch grows slowly with the mode): the splines reproduce the exact families to well below the
    numbering's model tolerance (0.3 %), which is all the refinement's fit needs (it only decides the numbers;
    the family reported is the exact model's at the fitted ratios). Each exact family costs a forward solve
    of every mode; the splines, a few microseconds."""

    def __init__(self, log_t: np.ndarray, log_ei: np.ndarray, families: np.ndarray):
        # A tensor-product cubic interpolant of every mode at once: interpolating along the tension and then
        # along EI gives the coefficients; a value is then basis(t)ᵀ C basis(EI), a few array operations for
        # all modes (a spline object per mode made the refinement cost more than the forward solves it saves).
        along_t = make_interp_spline(log_t, families, k=3, axis=0)
        self.basis_t = BSpline(along_t.t, np.eye(log_t.size), 3)
        self.slope_t = self.basis_t.derivative()
        if log_ei.size > 1:
            both = make_interp_spline(log_ei, along_t.c, k=3, axis=1)
            self.coefficients = np.moveaxis(both.c, 0, 1)  # (n_t, n_EI, n_modes): the spline keeps its axis first
            self.basis_ei = BSpline(both.t, np.eye(log_ei.size), 3)
            self.slope_ei = self.basis_ei.derivative()
        else:
            self.coefficients = along_t.c[:, 0, :]  # (n_t, n_modes)

    def __call__(self, x) -> np.ndarray:
        bt = self.basis_t(x[0])
        if len(x) > 1:
            return bt @ np.tensordot(self.coefficients, self.basis_ei(x[1]), axes=([1], [0]))
        return bt @ self.coefficients

    def gradient(self, x) -> np.ndarray:
        """d family / d x, shape (n_modes, len(x))."""
        if len(x) > 1:
            be = self.basis_ei(x[1])
            along_ei = np.tensordot(self.coefficients, be, axes=([1], [0]))  # (n_t, n_modes)
            slope_ei = np.tensordot(self.coefficients, self.slope_ei(x[1]), axes=([1], [0]))
            return np.column_stack([self.slope_t(x[0]) @ along_ei, self.basis_t(x[0]) @ slope_ei])
        return (self.slope_t(x[0]) @ self.coefficients)[:, None]


def _family(x, cable, attachments, tension, tension_model, n_modes):
    """The exact family at the log ratios ``x``. With a dashpot, its complex roots are refined from the last
    family solved for the same model (forward.damped's warm start: a candidate's ratios, and the next record's
    of a monitoring archive, move each root by a small part of its spacing; the start's checks send anything
    else to the certified solve), which costs a tenth of the solve from the undamped roots; the roots agree
    with it to 1e-9 (the secant's stop)."""
    t = math.exp(x[0])
    EI = cable.EI * math.exp(x[1]) if len(x) > 1 else cable.EI
    kwargs = {"EI": EI, "tension_model": tension_model[0], **tension_model[1]}
    if has_dampers(attachments):
        key = model_key(cable, tuple(attachments), n_modes, tension_model[0], tuple(sorted(tension_model[1].items())))
        start = _ROOTS.get(key)
        s = None
        if start is not None:
            s = batch_complex_modes(cable, attachments, tension * t, n_modes, certify=False, start=start,
                                    lost="nan", **kwargs)
        if s is None or not np.all(np.isfinite(s)):
            s = batch_complex_modes(cable, attachments, tension * t, n_modes, **kwargs)
        _ROOTS.put(key, s)
        return np.abs(s) / (2 * math.pi)
    return batch_frequencies(cable, attachments, tension * t, n_modes, **kwargs)


#: The complex roots of the last exact family solved per damped model in this process (:func:`_family`).
_ROOTS = BoundedCache(MAX_GRIDS)


def _modes_needed(f, cable, attachments, tension, lowest_ratio, tension_model):
    """Enough modes that the softest family in the search reaches past the highest peak (counted without the
    dashpots: a dashpot only raises the frequencies, towards those with its node pinned, so the count is
    never short, and it needs no complex solve)."""
    n = 8
    off = {"coefficients": np.zeros(len(attachments))} if has_dampers(attachments) else {}
    while True:
        soft = batch_frequencies(cable, attachments, tension * lowest_ratio, n, EI=cable.EI * 0.2,
                                 tension_model=tension_model[0], **tension_model[1], **off)
        if soft[-1] > 1.2 * f.max() or n > 400:
            return n
        n = int(n * 1.6)
