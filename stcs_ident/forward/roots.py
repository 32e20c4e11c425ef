"""Natural frequencies by the Wittrick–Williams count, for a batch.

For every (configuration, mode k) item the k-th natural frequency is first
bracketed by the count J alone (J(lo) < k ≤ J(hi)), then refined inside a
bracket that holds exactly one root and no pole (J(hi) − J(lo) = 1 and the
clamped-segment count J0 equal at both ends, so det K is continuous and
changes sign once there) by the Illinois variant of false position. Every
trial point updates the bracket by its count, so no root is ever missed or
taken twice; a step that does not halve the bracket within two tries is
replaced by bisection.
"""

from __future__ import annotations

import os

import numpy as np

from ..core.errors import ComputationError

try:  # the optional compiled kernel (setup.py); same numerics, no per-call overhead
    from . import _dsm_kernel
except ImportError:  # pragma: no cover - depends on the install
    _dsm_kernel = None

#: Set STCS_IDENT_NUMPY=1 to force the numpy path (the tests compare both).
FORCE_NUMPY = os.environ.get("STCS_IDENT_NUMPY", "") not in ("", "0")

RTOL = 2e-13  # relative bracket width at convergence (target 1e-12)
MAX_ITER = 200


def frequency_estimates(batch, idx, mode):
    """Pinned-beam estimate of ω for (possibly fractional) mode numbers."""
    length = batch.length[idx]
    H, m, EI = batch.H[idx], batch.m[idx], batch.EI[idx]
    n = np.asarray(mode, float)
    return n * np.pi / length * np.sqrt(H / m) * np.sqrt(1.0 + (n * np.pi / length) ** 2 * EI / H)


def _bracket(batch, config, mode):
    """Initial brackets from the count on a grid of estimates per configuration."""
    n_cfg = len(config)
    kmax = int(mode.max())
    ucfg, inverse = np.unique(config, return_inverse=True)
    grid_j = np.arange(kmax + 1) + 0.5
    gc = np.repeat(ucfg, kmax + 1)
    gw = frequency_estimates(batch, gc, np.tile(grid_j, len(ucfg)))
    gJ, gdet, gJ0 = batch.evaluate(gc, gw)
    gw, gJ, gdet, gJ0 = (a.reshape(len(ucfg), kmax + 1) for a in (gw, gJ, gdet, gJ0))
    gw, gJ, gdet, gJ0 = gw[inverse], gJ[inverse], gdet[inverse], gJ0[inverse]
    k = mode[:, None]
    below = gJ < k
    # the count is monotone in ω, so "below" is a prefix of the grid
    n_below = below.sum(axis=1)
    rows = np.arange(n_cfg)
    i_lo = np.maximum(n_below - 1, 0)
    has_lo = n_below > 0
    lo = np.where(has_lo, gw[rows, i_lo], 0.0)
    Jlo = np.where(has_lo, gJ[rows, i_lo], 0)
    J0lo = np.where(has_lo, gJ0[rows, i_lo], 0)
    flo = np.where(has_lo, gdet[rows, i_lo], np.nan)
    i_hi = np.minimum(n_below, kmax)
    has_hi = n_below <= kmax
    hi = np.where(has_hi, gw[rows, i_hi], np.nan)
    Jhi = np.where(has_hi, gJ[rows, i_hi], 0)
    J0hi = np.where(has_hi, gJ0[rows, i_hi], 0)
    fhi = np.where(has_hi, gdet[rows, i_hi], np.nan)
    step = 0
    while not has_hi.all():
        todo = np.flatnonzero(~has_hi)
        trial = 2.0 * np.maximum(lo[todo], gw[todo, -1])
        J, det, J0 = batch.evaluate(config[todo], trial)
        up = J >= mode[todo]
        t_up, t_dn = todo[up], todo[~up]
        hi[t_up], Jhi[t_up], J0hi[t_up], fhi[t_up] = trial[up], J[up], J0[up], det[up]
        has_hi[t_up] = True
        lo[t_dn], Jlo[t_dn], J0lo[t_dn], flo[t_dn] = trial[~up], J[~up], J0[~up], det[~up]
        gw[t_dn, -1] = trial[~up]
        step += 1
        if step > 60:
            raise ComputationError("could not bracket a natural frequency (count never reached the mode)")
    return [lo, hi, Jlo, Jhi, J0lo, J0hi, flo, fhi]


def solve_modes(batch, config, mode):
    """ω of mode ``mode[i]`` of configuration ``config[i]`` for every item i.

    Parameters
    ----------
    batch : CableBatch
    config : int array (n_items,)
    mode : int array (n_items,), mode numbers ≥ 1

    Returns
    -------
    omega : array (n_items,), rad/s
    """
    config = np.asarray(config, dtype=np.int64)
    mode = np.asarray(mode, dtype=np.int64)
    if use_kernel() and batch.n_dof <= 64:
        return _solve_compiled(batch, config, mode)
    lo, hi, Jlo, Jhi, J0lo, J0hi, flo, fhi = _bracket(batch, config, mode)
    n = len(config)
    side = np.zeros(n, dtype=np.int8)  # +1: hi moved last, −1: lo moved last
    stalled = np.zeros(n, dtype=np.int64)  # steps since the bracket last halved
    width_ref = hi - lo
    active = np.flatnonzero(hi - lo > RTOL * hi)
    for _ in range(MAX_ITER):
        if active.size == 0:
            break
        a = active
        width = hi[a] - lo[a]
        smooth = (Jhi[a] - Jlo[a] == 1) & (J0hi[a] == J0lo[a]) & np.isfinite(flo[a]) & np.isfinite(fhi[a])
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            secant = hi[a] - fhi[a] * width / (fhi[a] - flo[a])
        ok = smooth & (stalled[a] < 4) & (secant >= lo[a]) & (secant <= hi[a])
        # a step of at least a quarter of the tolerance, so that a secant
        # estimate already within round-off of one end closes the bracket
        step = 0.25 * RTOL * hi[a]
        secant = np.clip(secant, lo[a] + step, hi[a] - step)
        trial = np.where(ok, secant, 0.5 * (lo[a] + hi[a]))
        J, det, J0 = batch.evaluate(config[a], trial)
        up = J >= mode[a]
        u, d = a[up], a[~up]
        # Anderson–Björck: when the same end moves twice, scale the other
        # end's value so that the next secant step crosses the root
        again_u = u[side[u] == 1]
        again_d = d[side[d] == -1]
        flo[again_u] *= _ab_factor(det[up][side[u] == 1], fhi[again_u])
        fhi[again_d] *= _ab_factor(det[~up][side[d] == -1], flo[again_d])
        hi[u], Jhi[u], J0hi[u], fhi[u] = trial[up], J[up], J0[up], det[up]
        lo[d], Jlo[d], J0lo[d], flo[d] = trial[~up], J[~up], J0[~up], det[~up]
        side[u], side[d] = 1, -1
        new_width = hi[a] - lo[a]
        halved = new_width <= 0.5 * width_ref[a]
        width_ref[a] = np.where(halved, new_width, width_ref[a])
        stalled[a] = np.where(halved, 0, stalled[a] + 1)
        exact = det == 0
        lo[a[exact]] = hi[a[exact]] = trial[exact]
        active = a[hi[a] - lo[a] > RTOL * hi[a]]
    else:
        raise ComputationError(f"{active.size} natural frequencies did not converge in {MAX_ITER} iterations")
    return 0.5 * (lo + hi)


def _ab_factor(f_new, f_old):
    """Anderson–Björck scaling 1 − f_new / f_old, or ½ when that is not positive."""
    with np.errstate(divide="ignore", invalid="ignore"):
        m = 1.0 - f_new / f_old
    return np.where(m > 0, m, 0.5)


def use_kernel() -> bool:
    """Whether the compiled kernel is available and not switched off."""
    return _dsm_kernel is not None and not FORCE_NUMPY


def _solve_compiled(batch, config, mode):
    topo = batch.topology
    model = {"none": 0, "uniform": 1, "per-segment": 2}[topo.tension_model]
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)
    i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)
    raw, failed = _dsm_kernel.solve(
        topo.n_attachments, batch.n_dof, topo.n_h, int(topo.string), model,
        i64(batch.v_dof), i64(batch.t_dof), i64(batch.h_dof),
        f64(batch.length), f64(batch.m), f64(batch.EI), f64(batch.H), f64(batch.w), f64(batch.seg_len),
        f64(batch.masses), f64(batch._constant), f64(batch._scale), i64(config), i64(mode),
    )
    if failed:
        raise ComputationError(f"{failed} natural frequencies did not converge")
    return np.frombuffer(raw, dtype=np.float64).copy()
