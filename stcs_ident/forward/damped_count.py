"""The count of a damped configuration's complex modes, certified, and a lost mode found again
(:mod:`.damped`'s steps 3 and 4): the argument principle on a quadrilateral of the s-plane around the band,
the phase of det K(s) followed by bisection of the edges, and a search of the band for the roots the paths
missed. Also the scaled determinant and the secant method that the paths use.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..core.errors import ComputationError

__all__ = ["complete", "count_zeros", "determinant", "edge_parameters", "secant", "winding_number"]

SECANT_RTOL = 1e-10  # relative step at convergence (the next step's error is below 1e-15: order 1.6)
SECANT_ITER = 40
MAX_ARG_STEP = math.pi / 4  # phase change between neighbouring contour points
MAX_DAMPING = 0.5  # the count covers the modes damped less than this
DUPLICATE = 1e-8  # two roots closer than this (relative) are one
SEARCH_DEPTH = 30  # halvings of the band in the search for a lost mode
DEFLATE = 8  # known roots divided out when locating a lost one
LINE_POINTS = 64  # samples across the band's middle where a lost root is sought
MAX_CONTOUR_POINTS = 200_000


def determinant(batch, config: int, s: np.ndarray, t: float = 1.0) -> np.ndarray:
    """det of the scaled K(s) of configuration ``config``, the dashpots scaled by ``t``, at points ``s``."""
    s = np.asarray(s, dtype=complex)
    idx = np.full(s.size, config)
    with np.errstate(all="ignore"):  # far out on a contour an entry may overflow: a non-finite value is refined
        K, _ = batch.assemble(idx, -1j * s)
    v = batch.v_dof[1:-1]
    K[:, v, v] += t * batch.dashpots[config] * s[:, None]
    scale = batch._scale[config]
    with np.errstate(all="ignore"):
        return np.linalg.det(K * scale[:, None] * scale[None, :])


def secant(f, a: complex, fa: complex, b: complex) -> complex | None:
    """A root of ``f`` by the secant method from ``a`` (where f is ``fa``) and ``b``; None if it fails."""
    for _ in range(SECANT_ITER):
        fb = f(b)
        if not np.isfinite(fb):
            return None
        if fb == 0:
            return b
        if fb == fa:
            return None
        step = fb * (b - a) / (fb - fa)
        a, fa, b = b, fb, b - step
        if abs(step) <= SECANT_RTOL * abs(b):
            return b
    return None


def _region(omega: np.ndarray) -> tuple[float, float, float]:
    """The count's region below its top: Im s > ω₁/4, Re s < ω₁/2, damping ratio below MAX_DAMPING (its right
    edge half a mode spacing of a string from the axis, and sampled every ω₁/4)."""
    return 0.25 * omega[0], 0.5 * omega[0], MAX_DAMPING / math.sqrt(1 - MAX_DAMPING**2)


def count_zeros(batch, config: int, lo: float, hi: float, right: float, slope: float) -> int:
    """Eigenvalues with Im s in (lo, hi), Re s < right and −Re s < slope Im s: the winding number of det K
    plus its poles inside (the clamped-segment frequencies between lo and hi, J0)."""
    turns = winding_number(lambda z: determinant(batch, config, z), [right + 1j * lo, right + 1j * hi,
                                                                      (-slope + 1j) * hi, (-slope + 1j) * lo],
                           spacing=0.5 * right)
    _, _, J0 = batch.evaluate(np.array([config, config]), np.array([lo, hi]))
    return turns + int(J0[1] - J0[0])


def _inside(s: np.ndarray, lo: float, hi: float, right: float, slope: float) -> np.ndarray:
    return (s.imag > lo) & (s.imag < hi) & (s.real < right) & (s.real > -slope * s.imag)


def complete(batch, config: int, omega: np.ndarray, s: np.ndarray, n_modes: int) -> np.ndarray:
    """The first ``n_modes`` + 1 eigenvalues (by Im s) of the region, certified by the argument principle;
    a mode the paths lost (a path that ended on a damper's own overdamped root, or failed) is searched for
    by halving the band. Raises ComputationError when the count cannot be met."""
    lo, right, slope = _region(omega)
    roots = _unique(s[np.isfinite(s)])
    roots = roots[_inside(roots, lo, np.inf, right, slope)]
    hi = 0.0
    for _ in range(2 * n_modes + 8):
        roots = roots[np.argsort(roots.imag)]
        if roots.size > n_modes:
            hi = 0.5 * (roots[n_modes - 1].imag + roots[n_modes].imag)
        else:  # top modes lost: look above the highest found, a mean spacing further each time
            top = max(hi, roots[-1].imag if roots.size else omega[0])
            hi = top + 0.618 * (top - lo) / max(roots.size, 1)  # (not a fraction that halving returns to top)
        zeros = count_zeros(batch, config, lo, hi, right, slope)
        inside = int(np.count_nonzero(roots.imag < hi))
        if zeros < inside:
            raise ComputationError(f"the damped modes below {hi / (2 * math.pi):.6g} Hz number {zeros} by the "
                                   f"argument principle, but {inside} were found")
        if zeros == inside and roots.size > n_modes:
            return roots[:n_modes + 1]
        if zeros > inside:
            roots = _unique(np.concatenate([roots, _search(batch, config, lo, hi, right, slope, roots)]))
    raise ComputationError(f"a damped mode below {hi / (2 * math.pi):.6g} Hz was lost and not found again")


def _unique(s: np.ndarray) -> np.ndarray:
    s = s[np.argsort(s.imag)]
    if s.size < 2:
        return s
    keep = np.ones(s.size, bool)
    for i in range(1, s.size):
        keep[i] = np.all(np.abs(s[:i][keep[:i]] - s[i]) > DUPLICATE * abs(s[i]))
    return s[keep]


def _search(batch, config: int, lo: float, hi: float, right: float, slope: float, known: np.ndarray,
            depth: int = 0) -> np.ndarray:
    """The eigenvalues in the band (lo, hi) of the region that ``known`` lacks, by halving the band."""
    missing = count_zeros(batch, config, lo, hi, right, slope) - int(np.count_nonzero(
        _inside(known, lo, hi, right, slope)))
    if missing <= 0:
        return np.empty(0, complex)
    if missing == 1:
        root = _locate(batch, config, lo, hi, right, slope, known)
        if root is not None:
            return np.array([root])
    if depth >= SEARCH_DEPTH:
        raise ComputationError(f"a damped mode between {lo / (2 * math.pi):.6g} and {hi / (2 * math.pi):.6g} Hz "
                               "was lost and not found again")
    mid = _split(lo, hi, known)
    below = _search(batch, config, lo, mid, right, slope, known, depth + 1)
    above = _search(batch, config, mid, hi, right, slope, np.concatenate([known, below]), depth + 1)
    return np.concatenate([below, above])


def _split(lo: float, hi: float, known: np.ndarray) -> float:
    """A point between lo and hi near the middle, at least 2 % of the band from any known root's Im s (a root
    on a band's edge is counted in neither half)."""
    for u in (0.5, 0.45, 0.55, 0.4, 0.6, 0.35, 0.65, 0.3, 0.7):
        mid = lo + u * (hi - lo)
        if not np.any(np.abs(known.imag - mid) < 0.02 * (hi - lo)):
            return mid
    return lo + 0.5 * (hi - lo)


def _locate(batch, config: int, lo: float, hi: float, right: float, slope: float, known: np.ndarray):
    """The one eigenvalue of the band (lo, hi) that ``known`` lacks: the secant method on det K with the
    known roots divided out, from a few damping ratios at mid-band and from the smallest |det K| across it;
    None if it is not found there."""
    mid = 0.5 * (lo + hi)

    near = known[np.argsort(np.abs(known - 1j * mid))[:DEFLATE]]  # the nearest: the rest vary slowly

    def deflated(z):
        return determinant(batch, config, np.array([z]))[0] / np.prod(z - near)

    line = mid * (1j - slope * np.linspace(0.0, 1.0, LINE_POINTS))  # across the band's middle
    values = np.abs(determinant(batch, config, line))  # its smallest away from the known roots
    values[np.any(np.abs(line[:, None] - near[None, :]) < 0.02 * mid, axis=1)] = np.inf
    starts = [complex(-zeta * mid, mid) for zeta in (1e-4, 1e-3, 0.01, 0.1, 0.3)] + [line[np.argmin(values)]]
    for a in starts:
        b = a + 0.1j * (hi - lo)
        root = secant(deflated, a, deflated(a), b)
        if root is not None and _inside(np.array([root]), lo, hi, right, slope)[0] and not np.any(
                np.abs(known - root) <= DUPLICATE * abs(root)):
            return root
    return None


def edge_parameters(a: complex, b: complex, spacing: float) -> np.ndarray:
    """Where on the edge a → b (0 ≤ u < 1) the phase is first sampled: ``spacing`` apart near the imaginary
    axis, a quarter of the distance to it farther out (the roots there are damped, so det K varies on that
    scale), and, on an edge that crosses the axis, ever closer to it (Re s = ±spacing 4⁻ᵏ, k = 1 … 20):
    the poles of det K lie on the axis and the lightly damped roots beside it, at any distance from the
    crossing."""
    length = abs(b - a)
    u, at = [], 0.0
    while at < 1.0:
        u.append(at)
        z = a + (b - a) * at
        at += max(spacing, 0.25 * abs(z.real)) / length
    u = np.array(u)
    if a.imag == b.imag and min(a.real, b.real) < 0 < max(a.real, b.real):
        x = spacing * 4.0 ** -np.arange(1, 21)
        x = np.concatenate([-x, x])
        u = np.concatenate([u, (x - a.real) / (b.real - a.real)])
        u = np.unique(u[(u >= 0) & (u < 1)])
    return u


def winding_number(f, corners: Sequence[complex], spacing: float) -> int:
    """Turns of f(z) around 0 along the closed polygon ``corners`` (counter-clockwise), phase-tracked from
    the points of :func:`edge_parameters`, refined until no step changes the phase by more than π/4 (or
    the modulus by more than a factor e)."""
    ends = list(corners[1:]) + [corners[0]]
    z = np.concatenate([a + (b - a) * edge_parameters(a, b, spacing) for a, b in zip(corners, ends)])
    z = np.append(z, z[0])
    v = f(z)
    while True:
        step = np.angle(v[1:] / v[:-1])
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.abs(np.log(np.abs(v[1:] / v[:-1])))
        coarse = np.flatnonzero((np.abs(step) > MAX_ARG_STEP) | ~(ratio < 1.0))
        if coarse.size == 0:
            total = step.sum() / (2 * math.pi)
            return round(total)
        if z.size + coarse.size > MAX_CONTOUR_POINTS:
            raise ComputationError("the count of damped modes did not resolve (the determinant's phase varies too "
                                   "fast on the contour)")
        mid = 0.5 * (z[coarse] + z[coarse + 1])
        z = np.insert(z, coarse + 1, mid)
        v = np.insert(v, coarse + 1, f(mid))
