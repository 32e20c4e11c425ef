"""Complex modes of a cable with dampers, exact: the dynamic stiffness at a complex eigenvalue s.

A damper (:class:`~stcs_ident.core.model.Damper`) is an attachment with a dashpot: at its node it adds
``k + c s + m s²``. Every segment between nodes is the exact tensioned-beam (or string) element of
:mod:`.elements` evaluated at ω = −i s, and the sag-extensibility term (one additional tension ĥ, as in the
undamped solver) is kept, so K(s) is the undamped solver's matrix continued into the complex plane plus
``c s`` on the dampers' displacements. Its zeros are the eigenvalues s; a mode's frequency is |s|/2π and
its damping ratio −Re(s)/|s|.

How every mode is found, and none missed
-----------------------------------------
1. The undamped roots (dashpots removed, springs and masses kept) come from the Wittrick–Williams solver,
   which certifies their count.
2. Each is followed as the dashpots grow from 0 to their values (t = 0 … 1, c → t c): first in one step
   (a Möbius model of the path as the start of the secant method on det K(s)), else by geometric steps
   in t, each shortened whenever the secant method fails, jumps farther than a quarter of the
   distance to the neighbouring undamped roots, or lands farther from the prediction than half the step
   (another root: the damper's own overdamped modes cross the cable modes' paths).
   A path that ends on a root already found (two modes crossing closely) is solved again, from its
   pinned end, with the nearby roots found so far divided out of det K.
3. The count is certified by the argument principle: on the quadrilateral Im s ∈ [ω₁/4, ω_top],
   −Re s < 0.577 Im s (damping ratio below 0.5), Re s < ω₁/2 (ω_top midway between the highest
   requested mode and the next), the winding number of det K(s) plus the number of its poles inside (the
   clamped-segment frequencies, which are real: the J0 count of the undamped solver) is the number of
   eigenvalues inside. The phase of det K is sampled every ω₁/4 near the imaginary axis (a quarter of
   the distance to it farther out) and, where an edge crosses the axis, ever closer to it (poles lie on the axis, lightly damped roots beside it: a pole or root passed
   closer than the samples' spacing would turn the phase by 2π unseen), then refined until no step
   changes it by more than π/4. When the count exceeds the roots found (a path ended on one of the damper's own overdamped
   roots, which cross the cable modes' paths when the damper has a mass, or failed), the band is halved
   until each half lacks one root, found by the secant method with the known roots divided out; when it
   is below them, or the search fails, a ComputationError says so. The modes are returned by Im s.

The count covers every mode up to the band's top with a damping ratio below 0.5 (more damped roots, which
no record shows as a peak, and a path's overdamped end on the real axis, are left out of it).

Without a dashpot the result is the undamped solver's, bit for bit (s = iω, damping 0).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core.errors import ComputationError, ModelError
from ..core.model import Attachment, Cable
from ..core.planes import plane_overrides, plane_view
from .batch import build_batch, mode_items
from .damped_count import DUPLICATE, complete, determinant, secant
from .roots import FORCE_NUMPY, solve_modes

try:  # the optional compiled kernel (setup.py); same numerics, no per-call overhead
    from . import _damped_kernel
except ImportError:  # pragma: no cover - depends on the install
    _damped_kernel = None

__all__ = ["ComplexModes", "batch_complex_modes", "complex_modes"]

START = 0.01  # the first step's first-order shift, in units of the reach
GROWTH = 4.0  # largest ratio of consecutive t
MIN_RATIO = 1 + 1e-6
JUMP = 0.25  # of the distance to the neighbouring undamped roots: a longer step is refused
SMOOTH = 0.5  # a corrector landing farther from the prediction than this fraction of the step is refused
# (it found another root: the damper's own overdamped modes cross the cable modes' paths)
NEAR = 16  # roots within this many reaches of a path's start are divided out when it fell onto one


@dataclass(frozen=True)
class ComplexModes:
    """Complex eigenvalues s (Im s > 0), their frequencies |s|/2π (Hz) and damping ratios −Re(s)/|s|."""

    s: np.ndarray
    frequency: np.ndarray
    damping: np.ndarray


def complex_modes(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int = 6, *,
                  tension_model: str = "uniform", certify: bool = True, plane: str = "in") -> ComplexModes:
    """The first ``n_modes`` complex modes of one configuration (see the module docstring).

    Parameters
    ----------
    cable : Cable
    attachments : sequence of Attachment
        Dampers among them (:class:`~stcs_ident.core.model.Damper`).
    tension : float
        H, N.
    n_modes : int
    tension_model : {"uniform", "per-segment", "none"}
        As the undamped solver.
    certify : bool
        Check the count by the argument principle (costs about as much as the solve).
    plane : {"in", "out"}
        The plane of the motion (:func:`~stcs_ident.core.planes.plane_view`).

    Returns
    -------
    ComplexModes
        Ordered by mode (the undamped mode each was followed from).

    Raises
    ------
    ComputationError
        If a path does not converge or the count finds a mode the paths missed.
    """
    s = batch_complex_modes(cable, attachments, float(tension), n_modes, tension_model=tension_model,
                            certify=certify, plane=plane)
    return _modes(s)


def _modes(s: np.ndarray) -> ComplexModes:
    a = np.abs(s)
    return ComplexModes(s=s, frequency=a / (2 * math.pi), damping=-s.real / a)


def batch_complex_modes(cable: Cable, attachments: Sequence[Attachment], tension, n_modes: int = 6, *,
                        tension_model: str = "uniform", certify: bool = True, plane: str | None = "in",
                        start: np.ndarray | None = None, lost: str = "raise", **overrides) -> np.ndarray:
    """Complex eigenvalues s (rad/s) of many parameter sets, shape ``broadcast_shape + (n_modes,)``.

    Parameters as :func:`~stcs_ident.forward.batch_frequencies` (``plane`` too), with one more per-attachment
    override, ``coefficients`` (N s/m, the dashpots; 0 for an attachment without one).

    ``start``: the ``n_modes`` eigenvalues of a nearby parameter set (a fit's previous point), broadcast
    against the result. Each is then refined by the secant method (:func:`_warm`), and a parameter set whose
    roots do not all pass the warm start's checks is solved from its undamped roots as without it. Not with
    ``certify`` (a count needs the contour).

    ``lost``: ``"raise"`` (a :class:`~stcs_ident.core.errors.ComputationError` when a parameter set's roots
    cannot be found) or ``"nan"`` (that set's roots NaN, the others kept: a fit's extreme trial points).
    """
    if int(n_modes) < 1:
        raise ModelError(f"must be >= 1, got {n_modes}", field="n_modes")
    n_modes = int(n_modes)
    if plane is not None:
        overrides = plane_overrides(attachments, overrides, plane)
        cable, attachments = plane_view(cable, attachments, plane)
    shape, groups = build_batch(cable, attachments, tension, tension_model=tension_model, **overrides)
    total = math.prod(shape)
    out = np.empty((total, n_modes), dtype=complex)
    warm = None
    if start is not None and not certify and use_kernel():
        warm = np.broadcast_to(np.asarray(start, complex), shape + (n_modes,)).reshape(total, n_modes)
    for batch, sel in groups:
        cold = np.arange(len(sel))
        if warm is not None and batch.dashpots.any() and batch.n_dof <= 64:
            s, ok = _warm(batch, warm[sel], n_modes)
            out[sel[ok]] = s[ok]
            cold = np.flatnonzero(~ok)
        if cold.size:
            out[sel[cold]] = _cold(batch, cold, n_modes, certify, lost)
    return out.reshape(shape + (n_modes,))


def _warm(batch, start: np.ndarray, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """The roots of every damped configuration of ``batch`` refined from ``start`` (configs × n_modes) by the
    compiled kernel's secant method, and which configurations passed its checks: every root converged
    within a quarter of the distance from its start to the nearest other start (it cannot have jumped to a
    neighbour's), with Im s > 0, distinct and in the starts' order. A fit's trial points move the roots by a
    small fraction of their spacing, and a few determinants per root replace the undamped solve, the pinned
    solve and the path from the undamped root."""
    count = len(batch)
    configs = np.flatnonzero(batch.dashpots.any(axis=1))
    s = np.full((count, n_modes), np.nan, dtype=complex)
    ok = np.zeros(count, bool)
    if configs.size:
        raw, status = _damped_kernel.refine(*_kernel_problem(batch), np.ascontiguousarray(configs, dtype=np.int64),
                                            np.ascontiguousarray(start[configs], dtype=complex), int(n_modes))
        s[configs] = np.frombuffer(raw, dtype=complex).reshape(configs.size, n_modes)
        ok[configs] = np.frombuffer(status, dtype=np.intc) == 0
    return s, ok


def _cold(batch, configs: np.ndarray, n_modes: int, certify: bool, lost: str = "raise") -> np.ndarray:
    """The first ``n_modes`` roots of the configurations ``configs`` of ``batch``, each from its undamped
    roots, (len(configs), n_modes); ``lost`` as :func:`batch_complex_modes`'s."""
    n = n_modes + 1
    config = np.repeat(configs.astype(np.int64), n)
    mode = np.tile(np.arange(1, n + 1, dtype=np.int64), configs.size)
    omega_sub = solve_modes(batch, config, mode).reshape(configs.size, n)
    omega = np.zeros((len(batch), n))  # the kernel indexes the undamped roots by configuration
    omega[configs] = omega_sub
    s = 1j * omega_sub
    where = np.flatnonzero(batch.dashpots[configs].any(axis=1))  # rows of s
    damped = configs[where]
    if damped.size:
        pinned = _pinned_roots(batch, damped, n)
        if use_kernel() and batch.n_dof <= 64 and n_modes < MAX_KERNEL_MODES:
            s[where] = _solve_compiled(batch, damped, omega, pinned, n_modes, certify, lost)
        else:
            for i, c in enumerate(damped):
                try:
                    s[where[i]] = follow_roots(batch, int(c), omega[c], pinned[i], tolerant=certify)
                    if certify:
                        s[where[i]] = complete(batch, int(c), omega[c], s[where[i]], n_modes)
                except ComputationError:
                    if lost != "nan":
                        raise
                    s[where[i]] = np.nan
        s[where] = np.take_along_axis(s[where], np.argsort(s[where].imag, axis=1), axis=1)
    return s[:, :n_modes]


def _kernel_problem(batch) -> tuple:
    """The leading arguments of the compiled kernel's entry points for ``batch``."""
    topo = batch.topology
    model = {"none": 0, "uniform": 1, "per-segment": 2}[topo.tension_model]
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)
    i64 = lambda a: np.ascontiguousarray(a, dtype=np.int64)
    return (topo.n_attachments, batch.n_dof, topo.n_h, int(topo.string), model,
            i64(batch.v_dof), i64(batch.t_dof), i64(batch.h_dof),
            f64(batch.length), f64(batch.m), f64(batch.EI), f64(batch.H), f64(batch.w), f64(batch.seg_len),
            f64(batch.masses), f64(batch._constant), f64(batch._scale), f64(batch.dashpots))


def use_kernel() -> bool:
    """Whether the compiled kernel is available and not switched off (``STCS_IDENT_NUMPY=1``)."""
    return _damped_kernel is not None and not FORCE_NUMPY


_FAILURES = {
    1: "a damped mode could not be followed as the dampers grow",
    3: "the count of damped modes did not resolve (the determinant's phase varies too fast on the contour)",
    4: "the argument principle counts fewer damped modes than were found",
    6: "a damped mode was lost and not found again",
}
MAX_KERNEL_MODES = 511  # the kernel's fixed buffers

PIN = 1e8  # a pinning spring, in units of the scaled matrix's entries (order one): roots within ~1e-8


def _pinned_roots(batch, configs: np.ndarray, n: int) -> np.ndarray:
    """The first ``n`` roots (rad/s) of ``configs`` with every damper's node held by a stiff spring."""
    pinned = copy.copy(batch)
    pinned._constant = batch._constant.copy()
    nd = batch.n_dof
    rows, cols = np.nonzero(batch.dashpots)
    v = batch.v_dof[cols + 1]
    pinned._constant[rows, v * nd + v] += PIN / batch._scale[rows, v] ** 2
    config, mode = mode_items(0, len(batch), n)
    keep = np.isin(config, configs)
    return solve_modes(pinned, config[keep], mode[keep]).reshape(len(configs), n)


def _solve_compiled(batch, configs, omega, pinned, n_modes, certify, lost: str = "raise"):
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)
    raw, status = _damped_kernel.solve(*_kernel_problem(batch), np.ascontiguousarray(configs, dtype=np.int64),
                                       f64(omega), f64(pinned), int(n_modes), int(bool(certify)))
    status = np.frombuffer(status, dtype=np.intc)
    s = np.frombuffer(raw, dtype=complex).reshape(len(configs), n_modes + 1).copy()
    if status.any():
        if lost != "nan":
            raise ComputationError(_FAILURES[int(status[status != 0][0])])
        s[status != 0] = np.nan
    return s


def follow_roots(batch, config: int, omega: np.ndarray, pinned: np.ndarray, tolerant: bool = False) -> np.ndarray:
    """Each undamped root ``omega`` (rad/s) followed as the dashpots grow to their values (complex s).

    First in one step. As t grows from 0 to ∞, a root moves from s₀ = iω to iω∞, the root with the
    dampers' nodes pinned (``pinned``: its k-th root for the k-th mode, by interlacing). For one damper
    the path is a Möbius map of t (det K is linear in t, and the dynamic stiffness the damper sees has a
    zero at s₀ and a pole at iω∞), so 1/(s − s₀) = 1/(t δ₁) + 1/(iω∞ − s₀), δ₁ the first-order shift:
    the secant method's start (with a point beside it: a start at s₀ wandered off to other roots). If that fails or lands farther than ``JUMP`` times the distance to the
    neighbouring roots from the prediction, by geometric steps in t (:func:`_follow_in_steps`).
    """
    gaps = np.diff(np.concatenate(([0.0], omega, [2 * omega[-1] - omega[-2] if omega.size > 1 else 2 * omega[0]])))
    reach = JUMP * np.minimum(gaps[:-1], gaps[1:])
    out = np.empty(omega.size, dtype=complex)

    def det(z, t):
        return determinant(batch, config, np.array([z]), t)[0]

    for k, w in enumerate(omega):
        s0, h = 1j * w, 1e-7 * w
        f1 = det(s0, 1.0)
        first = -f1 * 2 * h / (det(s0 + h, 0.0) - det(s0 - h, 0.0))  # the first-order shift
        guess = s0 + 1 / (1 / first + 1 / (1j * (pinned[k] - w)))
        s = secant(lambda z: det(z, 1.0), guess, det(guess, 1.0), guess + 1e-3 * (guess - s0))  # local
        if s is None or abs(s - guess) > min(reach[k], SMOOTH * abs(guess - s0)):
            try:
                s = _follow_in_steps(det, s0, first, reach[k], k)
            except ComputationError:
                if not tolerant:
                    raise
                out[k] = np.nan  # lost: :func:`complete` searches for it
                continue
        if np.any(np.abs(out[:k] - s) <= DUPLICATE * abs(s)):  # (NaN compares false)
            # another path's root (a near crossing of two modes): that root divided out, from the same start
            found = out[:k][np.abs(out[:k] - s0) < NEAR * reach[k]]

            def deflated(z, found=found):
                return det(z, 1.0) / np.prod(z - found)

            s = None
            end, left = 1j * pinned[k], 0.3 * abs(1j * pinned[k] - s0)  # off the axis: poles sit on it
            for a, b in ((end - left, 0.5 * (s0 + end) - left), (s0, guess)):  # near its pinned end first
                s = secant(deflated, a, deflated(a), b)
                if s is not None and s.imag > 0 and not np.any(np.abs(out[:k] - s) <= DUPLICATE * abs(s)):
                    break
                s = None
            if s is None and not tolerant:
                raise ComputationError(f"the damped mode {k + 1} near {w / (2 * math.pi):.6g} Hz fell onto another "
                                       "mode's root and was not found apart from it")
            if s is None:
                s = np.nan
        out[k] = s
    return out


def _follow_in_steps(det, s0: complex, first: complex, reach: float, k: int) -> complex:
    """The root from s₀ at t = 0 to t = 1 by geometric steps in t (a dashpot's effect spans decades)."""
    t = min(1.0, START * reach / abs(first))  # where the first-order shift is a small fraction of the reach
    s = secant(lambda z: det(z, t), s0, det(s0, t), s0 + first * t)
    previous, ratio = None, GROWTH
    while s is not None and t < 1.0:
        t1 = min(1.0, t * ratio)
        if previous is None:
            guess = s + first * (t1 - t)
        else:  # the secant through the last two points
            guess = s + (s - previous[1]) * (t1 - t) / (t - previous[0])
        s1 = secant(lambda z, t1=t1: det(z, t1), s, det(s, t1), guess)
        if s1 is None or abs(s1 - s) > reach or abs(s1 - guess) > SMOOTH * abs(guess - s):
            ratio = math.sqrt(ratio)
            if ratio < MIN_RATIO:
                break
            continue
        previous, s, t, ratio = (t, s), s1, t1, min(ratio * ratio, GROWTH)
    if s is None or t < 1.0:
        raise ComputationError(f"the damped mode {k + 1} near {abs(s0) / (2 * math.pi):.6g} Hz could not be followed "
                               "as the dampers grow")
    return s
