"""The quick tension's exact model, solved without a nominal (:func:`stcs_ident.identify.quick.quick_tension`).

The inputs of ``stcs-ident tension`` *are* the nominal: there is nothing to judge them against, so the tension
is found, never started from a formula and then refused.

- **One mode, EI given** (EI 0: a string): f_n(T) = f is one equation in T, solved as a bracketed root. The
  bracket comes from a scan of the exact model's f_n over 10⁻⁴ … 1.5 times the taut string's tension (bending
  and sag only raise a mode above the string's, so the root lies below the string's tension; the scan widens
  upward if not). Where the scan finds several roots (a sagging cable's in-plane modes cross over as T falls),
  the highest is taken and the others said. Where bending alone puts f_n above f at every tension (a stiff
  member whose given EI is higher than its true one), f_n², linear in T for a pinned beam (f_n² = n²/(4 m l²)
  (T + n² π² EI / l²), docs/model.md) and nearly so with clamped ends, is extended below zero: the estimate is
  then negative, with its σ (EI's tolerance covers it); it is refused when even +3σ stays below zero.
  The σ is first order: σ_T² = (∂T/∂f σ_f)² + Σ_p (∂T/∂p w_p p)², by implicit differentiation of f_n² (central
  differences) for the length, the mass per length and a given EI with their relative tolerances w_p.
- **Two modes or more**: weighted least squares in (ln T, √EI) from the best point of a scan over a grid of T
  and EI (never from a formula). A given EI enters as a Gaussian prior of width its tolerance (EI is fitted
  with it, and the shares of EI's information from the frequencies and from the prior are reported); EI
  unknown is fitted alone (√EI ≥ 0: at 0 the modes do not see EI and the answer is a string's). The
  covariance is the fit's, with the tolerances of the length and the mass per length propagated
  (:func:`.nuisance.propagate`) and the frequencies' share scaled by the reduced χ² when the misfit is
  significant (:func:`.uncertainty.covariance_scale`), as ``identify`` does.
- **One mode, EI unknown**: no single tension follows. The string's tension (EI 0) is an upper bound; a
  lower one comes from the stiffest section a steel cable of this mass per length can have, a solid circular
  bar of area A = m/ρ: EI ≤ E A² / (4π) (ρ = 7850 kg/m³, E = 200 GPa). A tube, or a member lighter than steel
  for its stiffness (CFRP), can be stiffer: give EI then. Each end is widened by 3σ of the frequency and the
  tolerances, and the answer is that range, not a ±.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..core.formatting import plus_minus
from ..core.model import Boundary, Cable

__all__ = ["EI_CEILING_NOTE", "STEEL_DENSITY", "STEEL_MODULUS", "ExactAnswer", "Member", "bracketed_root",
           "exact_tension", "steel_bar_EI"]

#: Nominal steel: density (kg/m³) and Young's modulus (Pa) of the solid bar that bounds EI from the mass.
STEEL_DENSITY = 7850.0
STEEL_MODULUS = 2.0e11

#: The root's scan, as multiples of the taut string's tension of the mode.
SCAN = np.geomspace(1e-4, 1.5, 81)
#: The fit's scan: T as multiples of the lowest mode's string tension; EI as multiples of the largest EI that
#: bending alone allows (each mode's f_n at T = 0 on a pinned beam), plus 0.
FIT_SCAN_T = np.geomspace(1e-4, 1.5, 41)
FIT_SCAN_EI = np.concatenate([[0.0], np.geomspace(1e-9, 1.0, 19)])
#: Relative step of the central differences (the exact solver is converged to 1e-12: steps of 1e-5 keep the
#: derivatives to ~1e-7 while the curvature's error stays ~1e-10).
STEP = 1e-5
#: A tension below this share of the string's is "gone to zero" in a fit (its lower bound).
ZERO_TENSION = 1e-6

EI_CEILING_NOTE = ("assumes the stiffest section a steel cable of this mass per length can have, a solid circular "
                   "bar (EI = E A^2/(4 pi), A = m/rho, rho 7850 kg/m^3, E 200 GPa; a tube or a member stiffer than "
                   "steel for its weight can be stiffer: give EI then)")
UNSEEN_NOTE = ("EI is not seen by these modes (a string fits them as well, its chi2 within 1 of the fit with EI): "
               "a range, not a ±")


def force(value: float) -> str:
    """A force in N, kN or MN by its magnitude, 4 significant digits (as the tension command's table)."""
    return plus_minus(value, None, "N", digits=4)


def steel_bar_EI(mass_per_length: float) -> float:
    """EI (N m²) of a solid circular steel bar of this mass per length: E A²/(4π), A = m/ρ (I = A²/(4π))."""
    area = mass_per_length / STEEL_DENSITY
    return STEEL_MODULUS * area**2 / (4 * math.pi)


@dataclass(frozen=True)
class Member:
    """What the exact model holds fixed: geometry, mass, axial stiffness, ends and plane."""

    length: float
    mass: float
    EA: float | None
    inclination: float  # degrees
    boundary: str       # "clamped" or "pinned"
    plane: str          # "in" or "out"

    def other(self) -> Member:
        """The same member with the other end condition."""
        return replace(self, boundary="pinned" if self.boundary == "clamped" else "clamped")

    def cable(self) -> Cable:
        end = Boundary.clamped() if self.boundary == "clamped" else Boundary.pinned()
        return Cable(self.length, self.mass, 1.0, self.EA, math.radians(self.inclination), boundary_a=end,
                     boundary_b=end)

    def frequencies(self, tension, EI, modes, length_scale=1.0, mass_scale=1.0) -> np.ndarray:
        """f of ``modes`` (Hz), shape broadcast(tension, EI, scales) + (len(modes),)."""
        from ..forward.dsm import batch_frequencies

        modes = np.asarray(modes, int)
        out = batch_frequencies(self.cable(), [], np.asarray(tension, float), int(modes.max()), plane=self.plane,
                                EI=np.asarray(EI, float), length=self.length * np.asarray(length_scale, float),
                                mass_per_length=self.mass * np.asarray(mass_scale, float))
        return out[..., modes - 1]

    def string_tension(self, frequency: float, mode: int) -> float:
        return 4.0 * self.mass * self.length**2 * frequency**2 / mode**2


@dataclass(frozen=True)
class ExactAnswer:
    """The exact model's answer (:func:`exact_tension`).

    ``tension``/``uncertainty`` (N) or, with one mode and EI unknown, ``lower``/``upper`` (N, ``tension``
    None); ``failed`` with ``reason`` when no tension follows; ``EI`` (N m²) and its σ when fitted;
    ``notes`` to show; ``extra`` for the JSON.
    """

    tension: float | None = None
    uncertainty: float | None = None
    lower: float | None = None
    upper: float | None = None
    EI: float | None = None
    EI_uncertainty: float | None = None
    EI_source: str = ""
    notes: tuple[str, ...] = ()
    extra: dict = field(default_factory=dict)
    failed: bool = False
    reason: str | None = None


# ---- one mode: a root ---------------------------------------------------------------------------------------

def bracketed_root(g, a: float, b: float, ga: float, gb: float, rtol: float = 1e-13) -> float:
    """The root of ``g`` in [a, b] (g(a), g(b) of opposite signs) by the Illinois method (regula falsi whose
    retained end's value is halved when it is kept twice: superlinear on a smooth monotonic g, and it never
    leaves the bracket). Here rather than scipy's brentq so that one mode's answer does not import
    scipy.optimize (0.3 s of the command's 0.6 s)."""
    side = 0
    for _ in range(200):
        c = b - gb * (b - a) / (gb - ga) if gb != ga else 0.5 * (a + b)
        if not a < c < b and not b < c < a:
            c = 0.5 * (a + b)
        gc = g(c)
        if gc == 0 or abs(b - a) <= rtol * abs(c):
            return c
        if (gc < 0) == (gb < 0):  # c replaces b; a is kept
            b, gb = c, gc
            if side == -1:
                ga *= 0.5
            side = -1
        else:
            a, ga = c, gc
            if side == 1:
                gb *= 0.5
            side = 1
    return c


@dataclass(frozen=True)
class _Root:
    tension: float
    sigma_f: float               # σ of T from the frequency, N
    sigma_tol: dict              # σ of T from each tolerance, N
    others: tuple[float, ...]    # other roots, N
    extended: bool               # below zero (f_n² extended linearly)

    @property
    def sigma(self) -> float:
        return math.hypot(self.sigma_f, *self.sigma_tol.values())


def _root(member: Member, f: float, sigma: float, n: int, EI: float, tolerance: dict) -> _Root:
    """T with f_n(T) = f, and its σ; raises ValueError with the reason when there is none."""
    top = member.string_tension(f, n)
    grid = top * SCAN
    for _ in range(4):
        d = member.frequencies(grid, EI, [n])[:, 0] - f
        if np.any(d >= 0):
            break
        grid = grid * 10.0  # the mode stays below f even at 1.5x the string's tension: look higher
    else:
        raise ValueError(f"mode {n} stays below {f:g} Hz up to {force(grid[-1])}, 15 000 times the string's tension: "
                         "is the mode number right?")
    brackets = np.flatnonzero((d[:-1] < 0) != (d[1:] < 0))
    roots = []
    for i in brackets:
        roots.append(bracketed_root(lambda t: float(member.frequencies(t, EI, [n]).ravel()[0]) - f,
                                    grid[i], grid[i + 1], d[i], d[i + 1]))
    if roots:
        T, extended = max(roots), False
        at = T
    else:  # above f at every tension scanned: bending alone is too high; f_n² extended linearly below zero
        g0, g1 = member.frequencies(grid[:2], EI, [n])[:, 0] ** 2
        slope = (g1 - g0) / (grid[1] - grid[0])
        if not slope > 0:
            raise ValueError(f"mode {n} is above {f:g} Hz at every tension and does not fall with it")
        T, extended, at = grid[0] - (g0 - f * f) / slope, True, grid[0]
    # implicit derivatives of g = f_n² at the root (or at the scan's lowest tension when extended)
    keys = [k for k, v in (("length", member.length), ("mass_per_length", member.mass), ("EI", EI))
            if v and tolerance.get(k)]
    cols = {"T": (at * np.array([1 + STEP, 1 - STEP]), EI, 1.0, 1.0)}
    for k in keys:
        up = np.array([1 + STEP, 1 - STEP])
        cols[k] = (at, EI * up if k == "EI" else EI, up if k == "length" else 1.0,
                   up if k == "mass_per_length" else 1.0)
    g = {k: member.frequencies(*v[:2], [n], v[2], v[3])[..., 0] ** 2 for k, v in cols.items()}
    g_T = (g["T"][0] - g["T"][1]) / (2 * STEP * at)
    if extended:
        g_T = slope
    if not g_T > 0:
        raise ValueError(f"mode {n} does not rise with the tension at {force(T)}")
    sigma_tol = {k: abs((g[k][0] - g[k][1]) / (2 * STEP) * tolerance[k] / g_T) for k in keys}
    others = tuple(r for r in roots if abs(r - T) > 1e-6 * T)
    return _Root(float(T), float(2 * f * sigma / g_T), sigma_tol, others, extended)


def _one_mode(member: Member, f: float, sigma: float, n: int, EI: float, tolerance: dict) -> ExactAnswer:
    try:
        root = _root(member, f, sigma, n, EI, tolerance)
    except ValueError as err:
        return ExactAnswer(failed=True, reason=str(err))
    notes = []
    if root.others:
        notes.append("other tensions give the same frequency (a sagging cable's modes cross over as the tension "
                     f"falls): {', '.join(force(t) for t in sorted(root.others))}; the highest is taken")
    if root.extended:
        if root.tension + 3 * root.sigma < 0:
            return ExactAnswer(failed=True, reason=(
                f"bending alone puts mode {n} above {f:g} Hz at any tension: with the given EI the tension would "
                f"be {force(root.tension)}, below zero by more than 3σ ({force(root.sigma)}): is EI "
                "(or the mode number, the length) right?"))
        notes.append(f"bending alone (EI {EI:.4g} N m^2) puts mode {n} near or above {f:g} Hz: the tension is "
                     "small against it and, below zero, within its σ of a small positive one (EI's tolerance)")
    extra = {"uncertainty_from_frequencies": root.sigma_f,
             "uncertainty_from_tolerances": math.hypot(*root.sigma_tol.values()) if root.sigma_tol else 0.0,
             "tolerances_held": {k: tolerance[k] for k in root.sigma_tol}, "solved": "root of f_n(T) = f"}
    return ExactAnswer(root.tension, root.sigma, notes=tuple(notes), extra=extra)


def _range(member: Member, f: float, sigma: float, n: int, tolerance: dict) -> ExactAnswer:
    """One mode, EI unknown: [the root with the steel bar's EI − 3σ, the string's root + 3σ]."""
    held = {k: v for k, v in tolerance.items() if k != "EI"}
    ceiling = steel_bar_EI(member.mass)
    try:
        hi = _root(member, f, sigma, n, 0.0, held)
        lo = _root(member, f, sigma, n, ceiling, held)
    except ValueError as err:
        return ExactAnswer(failed=True, reason=str(err))
    upper = hi.tension + 3 * hi.sigma
    lower = max(0.0, lo.tension - 3 * lo.sigma)
    notes = ["EI unknown and one mode: a range, not a ±; its upper end is a string's tension (EI 0), its lower "
             + EI_CEILING_NOTE + "; each end widened by 3σ of the frequency and the tolerances"]
    if hi.others:
        notes.append("other tensions give the same frequency as a string (a sagging cable's crossover): "
                     f"{', '.join(force(t) for t in sorted(hi.others))}; the highest is taken")
    extra = {"lower": lower, "upper": upper, "string_tension": hi.tension, "steel_bar_EI": ceiling,
             "steel_bar_tension": lo.tension, "solved": "roots of f_n(T) = f with EI 0 and the steel bar's EI"}
    return ExactAnswer(lower=lower, upper=upper, EI_source="unknown (one mode): a range between EI 0 and a solid "
                       "steel bar's", notes=tuple(notes), extra=extra)


# ---- two modes or more: a fit -------------------------------------------------------------------------------

def _fit(member: Member, f: np.ndarray, sigma: np.ndarray, modes: np.ndarray, EI: float | None,
         tolerance: dict, fixed: bool = False) -> ExactAnswer:
    """Least squares in x = (ln(T/T_s), √EI / s_ref), or x = (ln(T/T_s),) with EI held.

    The frequencies' σ is scaled by the reduced χ² where their misfit is significant. Without a prior that is
    the χ² of the fit, on n − p degrees of freedom. With a prior the scale changes the estimate (the prior
    weighs more against scaled frequencies), so it is found self-consistently: refitted with the frequencies'
    σ scaled until the scale equals their χ² at that estimate over n less the parameters they fit (the trace
    of their hat matrix). A misnumbered record's modes that a free EI would bend to fit then keep the misfit
    that the prior's EI leaves. ``fixed``: fit with ``sigma`` as given, no scaling (that loop's step)."""
    if EI is not None and EI and tolerance.get("EI") and not fixed:
        return _prior_fit(member, f, sigma, modes, EI, tolerance)
    from scipy.optimize import least_squares

    from .nuisance import propagate
    from .uncertainty import covariance, covariance_scale

    k = int(np.argmin(modes))
    T_s = member.string_tension(f[k], int(modes[k]))
    EI_top = float(np.min(4 * member.mass * member.length**4 * f**2 / (modes.astype(float) ** 4 * math.pi**2)))
    s_ref = math.sqrt(T_s) * member.length / 100.0     # √EI at ξ = 100 and the string's tension
    width = None if EI is None else EI * tolerance.get("EI", 0.0)
    held = EI is not None and not width                 # EI 0, or given with tolerance 0
    prior = EI is not None and bool(width)

    def unpack(x):
        x = np.atleast_2d(x)
        T = T_s * np.exp(x[:, 0])
        E = np.full(T.shape, EI if held else 0.0) if held else (x[:, 1] * s_ref) ** 2
        return T, E

    def residuals(x, length_scale=1.0, mass_scale=1.0):
        T, E = unpack(x)
        r = (member.frequencies(T, E, modes, length_scale, mass_scale) - f) / sigma
        if prior:
            r = np.concatenate([r, ((E - EI) / width)[:, None]], axis=1)
        return r

    # the start: the best point of a scan (T × EI, with the prior's term when there is one)
    Tg = FIT_SCAN_T
    Eg = np.array([EI]) if held else np.concatenate([FIT_SCAN_EI * EI_top, [EI] if prior else []])
    TT, EE = np.meshgrid(Tg, Eg, indexing="ij")
    grid_x = np.column_stack([np.log(TT.ravel())] + ([] if held else [np.sqrt(EE.ravel()) / s_ref]))
    chi2 = np.sum(residuals(grid_x) ** 2, axis=1)
    x0 = grid_x[int(np.nanargmin(np.where(np.isfinite(chi2), chi2, np.inf)))]
    p = x0.size

    def jac_at(x):
        h = STEP * np.maximum(1.0, np.abs(x))
        pts = [x]
        for j in range(p):
            e = np.zeros(p)
            e[j] = h[j]
            lo = x - e if (j == 0 or x[j] - h[j] >= 0) else x
            pts += [x + e, lo]
        r = residuals(np.array(pts))
        J = np.empty((r.shape[1], p))
        for j in range(p):
            J[:, j] = (r[1 + 2 * j] - r[2 + 2 * j]) / (pts[1 + 2 * j][j] - pts[2 + 2 * j][j])
        return r[0], J

    bounds = ([-np.inf] * p, [np.inf] * p) if held else ([-np.inf, 0.0], [np.inf, np.inf])
    x0 = np.clip(x0, bounds[0], bounds[1])
    try:
        sol = least_squares(lambda x: residuals(x)[0], x0, jac=lambda x: jac_at(x)[1], bounds=bounds,
                            method="trf", x_scale=1.0, xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
    except (ValueError, ArithmeticError) as err:
        return ExactAnswer(failed=True, reason=f"the fit failed: {err}")
    x = sol.x
    T, E = (float(v[0]) for v in unpack(x))
    if not sol.success or not math.isfinite(T):
        return ExactAnswer(failed=True, reason=f"the fit did not converge ({sol.message})")
    if T < ZERO_TENSION * T_s:
        return ExactAnswer(failed=True, reason=(
            f"the fit's tension went to zero ({force(T)}, its lower bound): the modes say bending alone, or their "
            "numbers, the length or the mass are not what was given"))
    notes = []
    r, J = jac_at(x)
    base, _ = covariance(J)
    # the tolerances of the length and the mass per length, as nuisances (their Jacobian times their width)
    nuis = [(k, tolerance.get(k, 0.0)) for k in ("length", "mass_per_length") if tolerance.get(k)]
    A = np.zeros((r.size, len(nuis)))
    for j, (key, w) in enumerate(nuis):
        up = np.array([1 + STEP, 1 - STEP])
        rr = residuals(np.array([x, x]), up if key == "length" else 1.0, up if key == "mass_per_length" else 1.0)
        A[:, j] = (rr[0] - rr[1]) / (2 * STEP) * w
    n = f.size
    A_d = A[:n] if nuis else np.zeros((n, 1))
    # the frequencies' misfit: χ² of their own best fit (no prior: a prior at odds with them is said, not taken
    # for a misfit of theirs) under the data covariance the tolerances make, on n - p degrees of freedom
    if fixed:
        scale, chi2, dof = 1.0, gls_chi2(r[:n], A_d), n - p
    else:
        # the frequencies' misfit: χ² of their own best fit under the data covariance the tolerances make
        _, chi2 = propagate(J[:n], A_d, r[:n], base)
        dof = n - p
        scale, note = covariance_scale(chi2, dof, tolerances=bool(nuis))
        if note is not None and note.kind == "covariance_scaled":
            notes.append(str(note))
    if prior and abs(r[-1]) > 3:
        notes.append(f"the frequencies put EI at {E:.4g} N m^2, {abs(r[-1]):.1f}σ of its tolerance from the given "
                     f"{EI:.4g}: the given EI is likely wrong")
    # the frequencies' share scaled (their rows weighted by 1/√scale), the prior's and the tolerances' not
    weight = 1.0 / math.sqrt(scale)
    J = J.copy()
    J[:n] *= weight
    base, _ = covariance(J)
    C, _ = propagate(J[:n], A_d * weight, r[:n] * weight, base)
    sigma_T = T * math.sqrt(C[0, 0])
    extra = {"uncertainty_from_frequencies": T * math.sqrt(base[0, 0]),
             "uncertainty_from_tolerances": T * math.sqrt(max(C[0, 0] - base[0, 0], 0.0)),
             "tolerances_held": {key: w for key, w in nuis}, "reduced_chi2": chi2 / dof if dof > 0 else None,
             "covariance_scale": float(scale), "fitted": "tension" if held else "tension,EI", "chi2": float(r[:n] @ r[:n]),
             "solved": "least squares from a scan", "chi2_gls": gls_chi2(r[:n], A_d),
             "fitted_by_frequencies": float(np.trace(J[:n] @ np.nan_to_num(base, posinf=0.0) @ J[:n].T))}
    if held:
        return ExactAnswer(T, sigma_T, EI=EI, EI_source="given" if EI else "given as 0 (a string)", notes=tuple(notes),
                           extra=extra)
    sigma_EI = 2 * x[1] * s_ref**2 * math.sqrt(C[1, 1])
    if prior:
        info = J[:n].T @ J[:n]
        try:
            data_var = float(np.linalg.inv(info)[1, 1])
            p_data = 1.0 / data_var if data_var > 0 else 0.0
        except np.linalg.LinAlgError:
            p_data = 0.0
        p_prior = float(J[-1, 1] ** 2)
        share = p_data / (p_data + p_prior) if p_data + p_prior > 0 else 0.0
        extra["EI_shares"] = {"frequencies": share, "prior": 1.0 - share}
        source = (f"fitted with the given EI as a prior ({100 * tolerance['EI']:.3g} % 1σ): "
                  f"{100 * share:.0f} % from the frequencies, {100 * (1 - share):.0f} % from the prior")
    else:
        source = "fitted with the tension (two modes or more, no EI given)"
    return ExactAnswer(T, sigma_T, EI=E, EI_uncertainty=sigma_EI, EI_source=source, notes=tuple(notes), extra=extra)


def gls_chi2(r: np.ndarray, A: np.ndarray) -> float:
    """rᵀ V⁻¹ r with V = I + A Aᵀ (the data covariance with the tolerances' share, in units of σ)."""
    V = np.eye(r.size) + A @ A.T
    try:
        return float(r @ np.linalg.solve(V, r))
    except np.linalg.LinAlgError:
        return float(r @ np.linalg.lstsq(V, r, rcond=None)[0])


def _prior_fit(member, f, sigma, modes, EI, tolerance) -> ExactAnswer:
    """:func:`_fit` with EI's prior and the frequencies' σ scaled self-consistently (see there)."""
    from .uncertainty import covariance_scale

    scale, note, chi2, dof = 1.0, None, 0.0, 0
    for _ in range(8):
        answer = _fit(member, f, sigma * math.sqrt(scale), modes, EI, tolerance, fixed=True)
        if answer.failed:
            return answer
        chi2 = answer.extra["chi2_gls"] * scale  # in units of the stated σ
        dof = f.size - answer.extra["fitted_by_frequencies"]
        new, note = covariance_scale(chi2, dof if dof >= 0.5 else 0, tolerances=bool(answer.extra["tolerances_held"]))
        if abs(new - scale) <= 0.01 * scale:
            break
        scale = new
    if scale > 1 and note is not None:
        answer = replace(answer, notes=(str(note), *answer.notes))
    return replace(answer, extra={**answer.extra, "covariance_scale": float(scale),
                                  "reduced_chi2": chi2 / dof if dof >= 0.5 else None})


# ---- the answer ---------------------------------------------------------------------------------------------

def _solve(member, f, sigma, modes, EI, tolerance) -> ExactAnswer:
    if f.size == 1:
        if EI is None:
            return _range(member, float(f[0]), float(sigma[0]), int(modes[0]), tolerance)
        answer = _one_mode(member, float(f[0]), float(sigma[0]), int(modes[0]), EI, tolerance)
        return replace(answer, EI=EI, EI_source="given" if EI else "given as 0 (a string)")
    answer = _fit(member, f, sigma, modes, EI, tolerance)
    if EI is not None or answer.failed:
        return answer
    # EI unknown: do the modes see it? A string (EI 0) that fits them as well (Δχ² < 1) says not; the answer is
    # then the range between the string's tension and the one with a solid steel bar's EI, as with one mode
    held = {k: v for k, v in tolerance.items() if k != "EI"}
    string = _fit(member, f, sigma, modes, 0.0, held)
    if string.failed or string.extra["chi2"] - answer.extra["chi2"] >= 1.0:
        return answer
    ceiling = steel_bar_EI(member.mass)
    bar = _fit(member, f, sigma, modes, ceiling, held)
    upper = string.tension + 3 * string.uncertainty
    lower = 0.0 if bar.failed else max(0.0, bar.tension - 3 * bar.uncertainty)
    notes = (UNSEEN_NOTE + "; its upper end is a string's tension (EI 0), its lower " + EI_CEILING_NOTE
             + "; each end widened by 3σ",)
    extra = {"lower": lower, "upper": upper, "string_tension": string.tension, "steel_bar_EI": ceiling,
             "steel_bar_tension": None if bar.failed else bar.tension, "fitted": "tension (EI 0; the steel bar's)",
             "solved": "least squares with EI 0 and with the steel bar's EI"}
    return ExactAnswer(lower=lower, upper=upper, EI_source="not seen by these modes: a range between EI 0 and a "
                       "solid steel bar's", notes=notes, extra=extra)


def exact_tension(member: Member, frequencies, sigma, modes, EI: float | None, tolerance: dict) -> ExactAnswer:
    """The exact model's tension for ``member`` from measured ``frequencies`` (Hz, 1σ ``sigma``) of ``modes``.

    ``EI``: N m², or None (unknown); ``tolerance``: relative 1σ of ``length``, ``mass_per_length`` and a given
    ``EI`` (0 or absent: exact). The answer under the other end condition is in ``extra["other_boundary"]``
    (``boundary``, ``tension``, ``uncertainty``, ``change``, or ``lower``/``upper``; ``note`` says whether the two
    differ by more than the σ).
    """
    f, sigma, modes = (np.asarray(v, float) for v in (frequencies, sigma, modes))
    modes = modes.astype(int)
    answer = _solve(member, f, sigma, modes, EI, tolerance)
    if answer.failed:
        return answer
    other = _solve(member.other(), f, sigma, modes, EI, tolerance)
    ends = member.other().boundary
    if other.failed:
        said = {"boundary": ends, "failed": other.reason}
        return replace(answer, extra={**answer.extra, "other_boundary": said})
    said = {"boundary": ends, "tension": other.tension, "uncertainty": other.uncertainty}
    if other.tension is None:
        said = {"boundary": ends, "lower": other.lower, "upper": other.upper}
    if answer.tension is not None and other.tension is not None and answer.tension > 0:
        change = other.tension / answer.tension - 1
        apart = abs(other.tension - answer.tension) > answer.uncertainty
        said["change"] = change
        said["note"] = (f"with {ends} ends {force(other.tension)} ({100 * change:+.3g} %), "
                        + ("more than the 1σ apart: the end condition matters here" if apart else "within the 1σ"))
    elif answer.lower is not None and other.lower is not None:
        said["note"] = f"with {ends} ends between {force(other.lower)} and {force(other.upper)}"
    return replace(answer, extra={**answer.extra, "other_boundary": said})
