"""The source paper's method: contours of the frequency surfaces over a grid of two parameters.

For two parameter ratios (r1, r2) on a grid (201 × 201 by default) the
batch solver gives every measured mode's frequency surface f_k(r1, r2). Its
contour at the measured value f_k^meas is the curve of pairs that reproduce
that mode. With perfect data all contours cross at one point; with real
data they pass near one another in a small region. Here that is made
precise with the frequency uncertainties σ_k: each contour is a band
|f_k − f_k^meas| ≤ τ σ_k, and with z_k = (f_k − f_k^meas)/σ_k

- the **estimate** (centre) is the point where the bands, narrowed
  together, meet last: the minimiser r* of max_k |z_k(r)|, with τ* that
  minimum (0 for perfect data, so r* is then the true pair);
- the **intersection region** is where every contour passes within one
  uncertainty more than at the centre, max_k |z_k| ≤ τ* + 1 (the connected
  part around r*), and its half extent along each axis is the uncertainty.

The σ_k are those of the measurements, scaled like the least-squares
covariance by the reduced χ² when the misfit is larger than they explain;
otherwise real data, whose contours miss each other by tens of rounding
units, would give a region far smaller than the scatter warrants. The grid
is widened when the region reaches its edge, and a finer grid is laid over
a region only a few cells across to measure it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage
from scipy.optimize import minimize

from ..core.errors import InputError
from ..core.notes import Note, point
from ..core.settings import Settings
from .lsq import finish, local_fit, mirror_images, nearest_nominal
from .problem import Problem
from .result import IdentificationResult
from .uncertainty import covariance_scale

#: Sentence of the ``covariance_scaled`` note here: the bands are widened, and the covariance with them.
SCALED_BANDS = ("the misfit is {misfit:.3g} times the stated frequency uncertainties (reduced chi2 {value:.3g}, "
                "{dof} degrees of freedom): the contour bands are widened by its square root")

#: Points per side of the finer grid laid over a small region.
ZOOM_POINTS = 101
#: A region fewer cells across than this is measured again on a finer grid.
MIN_CELLS = 12


@dataclass(frozen=True)
class ContourSweep:
    """Frequency surfaces of two parameters on a grid, and the contours' intersection.

    Attributes
    ----------
    parameters : tuple of two Parameter
    axes : tuple of two ndarray
        Grid values of the two variables (n1,) and (n2,).
    surfaces : ndarray (n1, n2, n_data)
        Model frequency of every measured mode (Hz) at every grid point.
    measured : ndarray (n_data,)
    sigma : ndarray (n_data,)
        Band half-widths used, Hz (measurement uncertainty × √scale).
    labels : list of str
        ``"<test> mode <k>"`` per measured frequency.
    misfit : ndarray (n1, n2)
        max_k |f_k − f_k^meas| / σ_k.
    level : float
        τ* + 1: the region is ``misfit <= level``.
    region : ndarray of bool (n1, n2)
        The connected intersection region around the estimate.
    estimate : ndarray (2,)
    extent : ndarray (2,)
        Half extent of the region along each axis (the uncertainty).
    centroid : ndarray (2,)
        Mean of the region's grid points (for comparison with ``estimate``).
    zoom : ContourSweep or None
        The finer grid over the region, when one was needed.
    """

    parameters: tuple
    axes: tuple[np.ndarray, np.ndarray]
    surfaces: np.ndarray = field(repr=False)
    measured: np.ndarray
    sigma: np.ndarray
    labels: list[str]
    misfit: np.ndarray = field(repr=False)
    level: float
    region: np.ndarray = field(repr=False)
    estimate: np.ndarray
    extent: np.ndarray
    centroid: np.ndarray
    zoom: ContourSweep | None = None

    def contour_lines(self, k: int) -> list[np.ndarray]:
        """Polylines (m, 2) of mode ``k``'s contour at its measured value, in variable units."""
        from contourpy import contour_generator

        y, x = np.meshgrid(self.axes[1], self.axes[0])
        gen = contour_generator(x, y, self.surfaces[..., k])
        return [np.asarray(line) for line in gen.lines(float(self.measured[k]))]

    @property
    def touches_edge(self) -> bool:
        r = self.region
        return bool(r[0].any() or r[-1].any() or r[:, 0].any() or r[:, -1].any())


def fit_contour(problem: Problem, *, grid: tuple[int, int] = (201, 201), ranges=None, scale_rule: str = "auto",
                max_widen: int = 3, settings: Settings | None = None) -> IdentificationResult:
    """The paper's contour-intersection estimate of two parameters.

    Parameters
    ----------
    problem : Problem
        Exactly two free parameters (a tension and EI; two attachment
        positions; ...), any number of tests and modes.
    grid : (int, int)
        Grid points along each parameter.
    ranges : mapping or sequence of two (lower, upper), optional
        Grid ranges in variable units, by parameter name or kind, or in
        order; default each kind's grid span (:attr:`stcs_ident.core.kinds.Kind.grid`) clipped to the bounds.
    scale_rule : {"auto", "birge", "never"}
    max_widen : int
        How many times the grid may be widened when the region reaches its
        edge.
    settings : Settings, optional
        Recorded in the result (default: the problem's tension model and
        ``scale_rule``); its ``scale_rule`` then replaces ``scale_rule``.

    Returns
    -------
    IdentificationResult
        ``method="contour"``; ``uncertainty`` is the region's half extent;
        ``sweep`` is the :class:`ContourSweep` (for the figures).
    """
    if len(problem.parameters) != 2:
        raise InputError(f"the contour method sweeps exactly two parameters, got {len(problem.parameters)} "
                         f"({', '.join(problem.names)}); use method lsq", field="params")
    n1, n2 = (int(g) for g in grid)
    if min(n1, n2) < 11:
        raise InputError(f"needs at least 11 points per side, got {grid}", field="grid")
    if settings is None:
        settings = Settings(tension_model=problem.tension_model, scale_rule=scale_rule)
    scale_rule = settings.scale_rule
    lo, hi = _ranges(problem, ranges)
    notes = []
    axes = (np.linspace(lo[0], hi[0], n1), np.linspace(lo[1], hi[1], n2))
    F = _surfaces(problem, axes)
    chi2_grid = np.sum(((F - problem.measured) / problem.sigma) ** 2, axis=-1)
    i0 = np.unravel_index(np.nanargmin(np.where(np.isfinite(chi2_grid), chi2_grid, np.inf)), chi2_grid.shape)
    _, chi2_min = local_fit(problem, np.array([axes[0][i0[0]], axes[1][i0[1]]]), 100)
    scale, scale_note = covariance_scale(chi2_min, problem.n_data - 2, scale_rule)
    if scale_note:
        notes.append(replace(scale_note, template=SCALED_BANDS) if scale_note.kind == "covariance_scaled"
                     else scale_note)
    sigma = problem.sigma * np.sqrt(scale)
    centre, tau = _minimax(problem, F, axes, sigma)
    centre, alternatives = _mirror_choice(problem, centre, tau, sigma)
    if alternatives:
        notes.append(Note.make("mirror_image", "the mirror image explains the data equally well (the one nearest "
                               "the nominal values is reported): {points}",
                               points=[point(problem.names, a) for a in alternatives]))
    sweep = _sweep(problem, axes, F, sigma, centre, tau)
    for _ in range(max_widen):
        grow = _widened(problem, axes, sweep)
        if grow is None:
            break
        notes.append(Note.make("grid_widened", "the intersection region reached the edge of the grid: grid "
                               "widened to {low_1:.4g}-{high_1:.4g} x {low_2:.4g}-{high_2:.4g}",
                               parameters=problem.names, low_1=float(grow[0][0]), high_1=float(grow[0][-1]),
                               low_2=float(grow[1][0]), high_2=float(grow[1][-1])))
        axes, F = grow, _surfaces(problem, grow)
        sweep = _sweep(problem, axes, F, sigma, centre, tau)
    if _widened(problem, axes, sweep) is not None:
        notes.append(Note.make("region_at_edge", "the intersection region still reaches the edge of the grid: its "
                               "extent is a lower bound"))
    zoom = _zoom(problem, sweep)
    if zoom is not None:
        sweep = _replace_zoom(sweep, zoom)
    extent = sweep.extent
    parts = ndimage.label(sweep.misfit <= sweep.level)[1]
    if parts > 1:
        notes.append(Note.make("separate_regions", "the contours nearly meet in {value} separate regions; the one "
                               "around the estimate is reported", value=int(parts)))
    notes.append(Note.make("contour_centre", "contour centre: every mode within {value:.3g} band widths; region: "
                           "within {level:.3g}", value=float(tau), level=float(tau + 1)))
    chi2 = float(problem.chi2(centre[None, :])[0])
    return finish(problem, centre, chi2, "contour", notes=notes, uncertainty=extent, sweep=sweep, scale=scale,
                  alternatives=alternatives, settings=settings)


def _ranges(problem: Problem, ranges) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = [], []
    for j, q in enumerate(problem.parameters):
        given = None
        if isinstance(ranges, dict):
            given = next((ranges[k] for k in (q.name, q.kind, q.key) if k in ranges), None)
        elif ranges is not None:
            given = ranges[j]
        if given is None:
            default = q.spec.grid if q.is_ratio or q.is_fixity else (q.lower, q.upper)
            given = (max(default[0], q.lower), min(default[1], q.upper))
        a, b = float(given[0]), float(given[1])
        if not a < b:
            raise InputError(f"the grid range must be increasing, got ({a:g}, {b:g})", field=f"ranges.{q.name}")
        lo.append(max(a, q.lower))
        hi.append(min(b, q.upper))
    return np.array(lo), np.array(hi)


def _surfaces(problem: Problem, axes) -> np.ndarray:
    a, b = np.meshgrid(axes[0], axes[1], indexing="ij")
    X = np.stack([a.ravel(), b.ravel()], axis=1)
    return problem.predict(X).reshape(a.shape + (problem.n_data,))


def _misfit(problem: Problem, F: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    M = np.max(np.abs(F - problem.measured) / sigma, axis=-1)
    return np.where(np.isfinite(M), M, np.inf)


def _minimax(problem: Problem, F: np.ndarray, axes, sigma: np.ndarray) -> tuple[np.ndarray, float]:
    """The point whose worst mode is nearest its contour: min over r of max_k |z_k(r)|.

    Grid minimum, then SLSQP on the smooth epigraph form (minimise t with
    −t ≤ z_k(r) ≤ t).
    """
    M = _misfit(problem, F, sigma)
    i, j = np.unravel_index(np.argmin(M), M.shape)
    x0 = np.array([axes[0][i], axes[1][j]])
    ratio = problem.sigma / sigma

    def z(x):
        return (problem.predict(x) - problem.measured) / sigma

    def dz(x):
        return problem.jacobian(x) * ratio[:, None]

    def constraints(v):
        zz = z(v[:2])
        return np.concatenate([v[2] - zz, v[2] + zz])

    def constraints_jac(v):
        J = dz(v[:2])
        one = np.ones((J.shape[0], 1))
        return np.vstack([np.hstack([-J, one]), np.hstack([J, one])])

    scale = np.maximum(np.abs(x0), 1e-3)
    best_x, best_t = x0, float(M[i, j])
    v0 = np.concatenate([x0, [best_t]])
    for _ in range(3):
        res = minimize(lambda v: v[2], v0, jac=lambda v: np.array([0.0, 0.0, 1.0]), method="SLSQP",
                       bounds=[(problem.lower[0], problem.upper[0]), (problem.lower[1], problem.upper[1]), (0, None)],
                       constraints=[{"type": "ineq", "fun": constraints, "jac": constraints_jac}],
                       options={"ftol": 1e-15, "maxiter": 200})
        x = res.x[:2]
        t = float(np.max(np.abs(z(x))))
        if t < best_t:
            best_x, best_t = x, t
        if np.all(np.abs(x - v0[:2]) <= 1e-13 * scale):
            break
        v0 = np.concatenate([best_x, [best_t]])
    return best_x, best_t


def _mirror_choice(problem: Problem, centre: np.ndarray, tau: float, sigma: np.ndarray):
    """Among the centre and its equally good mirror images, the one nearest the nominal values."""
    mirrors = mirror_images(problem, centre)
    if not mirrors:
        return centre, []
    M = np.max(np.abs(problem.predict(np.array(mirrors)) - problem.measured) / sigma, axis=1)
    same = [m for m, t in zip(mirrors, M) if abs(t - tau) <= 1e-6 * max(1.0, tau)]
    order = nearest_nominal(problem, [centre, *same])
    return order[0], order[1:]


def _sweep(problem: Problem, axes, F: np.ndarray, sigma: np.ndarray, centre: np.ndarray, tau: float) -> ContourSweep:
    """The region around ``centre`` on this grid, with its extent."""
    M = _misfit(problem, F, sigma)
    level = tau + 1.0
    labels, _ = ndimage.label(M <= level)
    i = int(np.argmin(np.abs(axes[0] - centre[0])))
    j = int(np.argmin(np.abs(axes[1] - centre[1])))
    if labels[i, j] == 0:
        region = np.zeros_like(M, bool)
        region[i, j] = True
    else:
        region = labels == labels[i, j]
    ii, jj = np.nonzero(region)
    cells = np.array([axes[0][1] - axes[0][0], axes[1][1] - axes[1][0]])
    extent = np.array([(axes[0][ii].max() - axes[0][ii].min()), (axes[1][jj].max() - axes[1][jj].min())]) / 2
    extent = np.maximum(extent, cells / 2)
    centroid = np.array([axes[0][ii].mean(), axes[1][jj].mean()])
    names = [f"{m.name} {label}" for m in problem.measurements for label in m.labels()]
    return ContourSweep(problem.parameters, axes, F, problem.measured, sigma, names, M, level, region,
                        np.asarray(centre, float), extent, centroid)


def _widened(problem: Problem, axes, sweep: ContourSweep):
    """Wider axes when the region reaches an edge that is not a bound, else None."""
    r = sweep.region
    edges = [(r[0].any(), r[-1].any()), (r[:, 0].any(), r[:, -1].any())]
    new, changed = [], False
    for d, (low, high) in enumerate(edges):
        a, b = axes[d][0], axes[d][-1]
        width = b - a
        lo_b, hi_b = problem.lower[d], problem.upper[d]
        if low and a > lo_b:
            a, changed = max(lo_b, a - width), True
        if high and b < hi_b:
            b, changed = min(hi_b, b + width), True
        new.append(np.linspace(a, b, axes[d].size))
    return tuple(new) if changed else None


def _zoom(problem: Problem, sweep: ContourSweep) -> ContourSweep | None:
    """A finer grid over a region only a few cells across (None when not needed)."""
    axes = sweep.axes
    cells = np.array([axes[0][1] - axes[0][0], axes[1][1] - axes[1][0]])
    if np.all(2 * sweep.extent / cells >= MIN_CELLS):
        return None
    half = np.maximum(2 * sweep.extent, 2 * cells)
    for _ in range(4):
        lo = np.maximum(sweep.estimate - half, problem.lower)
        hi = np.minimum(sweep.estimate + half, problem.upper)
        zaxes = (np.linspace(lo[0], hi[0], ZOOM_POINTS), np.linspace(lo[1], hi[1], ZOOM_POINTS))
        F = _surfaces(problem, zaxes)
        zoom = _sweep(problem, zaxes, F, sweep.sigma, sweep.estimate, sweep.level - 1.0)
        if not zoom.touches_edge:
            return zoom
        half = 2 * half
    return zoom


def _replace_zoom(sweep: ContourSweep, zoom: ContourSweep) -> ContourSweep:
    return replace(sweep, zoom=zoom, extent=zoom.extent, centroid=zoom.centroid)
