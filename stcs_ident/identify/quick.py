"""The quick answer: a cable's tension from a length, a mass and one or more frequencies, no campaign file.

:func:`quick_tension` puts side by side, each with its 1σ:

- ``taut_string``: T = 4 m l² f_n² / n² (the vibrating string; ignores bending and sag; its note gives its
  excess over the exact model's tension; with EI given, left out when that exceeds :data:`TAUT_MAX_BIAS`);
- ``beam``: the tensioned-beam formulas the exact solver is checked against
  (:mod:`stcs_ident.forward.reference`), inverted for the tension, when EI is given:
  pinned ends exactly, clamped ends by the large-ξ expansion;
- ``zui1996``: the practical formulas of Zui, Shinke & Namita (1996) (:mod:`.zui`, coefficients as quoted by a
  public implementation), with EI given and clamped ends, each answer with the formula's error band measured
  against the exact model;
- ``mehrabi1998``: Mehrabi & Tabatabai (1998): no source of its coefficients could be read, and they are not
  reconstructed from memory: the key stays (the JSON contract), ``tension`` None, with :data:`UNSOURCED`;
- ``exact``: the exact dynamic-stiffness model (sag-extensibility with EA, inclination, the chosen ends),
  solved without a nominal (:mod:`.quick_exact`): one mode with EI given, a bracketed root; two modes or
  more, a least-squares fit from a scan, a given EI its prior; one mode (or modes that do not see EI) with EI
  unknown, a range (``lower``, ``upper``) between a solid steel bar's EI and a string's; the other end
  condition beside it; ``plane="out"`` fits the out-of-plane family (no sag-extensibility: EA plays no part).

Uncertainty: every formula's σ is the frequency σ propagated through dT/df (first order); with several
modes the per-mode estimates are averaged and the σ of the mean combines that propagation with their
scatter, σ² = σ_prop² + s²/k (s the sample standard deviation of the k estimates): a spread larger than
the frequencies explain (a taut-string tension rising with the mode, from bending) then shows in the σ.
The exact model's σ is first order with one mode, the fit's covariance with more (its frequencies' share
scaled by the reduced χ² when the misfit is significant, as ``identify`` does).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ..core import kinds
from ..core.errors import ComputationError, InputError
from ..core.model import finite_number, frequency, in_band, mode_number
from ..core.notes import Note
from ..core.planes import PLANES
from ..core.result import Result
from ..forward.statics import irvine_lambda2
from .problem import printed_step
from .quick_exact import Member, exact_tension
from .quick_formulas import (
    clamped_beam_frequency,
    clamped_beam_tension,
    pinned_beam_tension,
    taut_string_tension,
)
from .zui import SOURCE as ZUI_SOURCE
from .zui import zui_tension

BOUNDARIES = ("clamped", "pinned")

#: Where each method comes from (shown in the JSON and in docs/tension.md).
SOURCES = {
    "taut_string": "taut string, f_n = (n / 2l) sqrt(T/m) (the vibrating string); "
                   "stcs_ident.forward.reference.taut_string",
    "beam": "tensioned beam: pinned ends f_n = f_n^string sqrt(1 + n^2 pi^2 EI / (T l^2)) (exact); clamped ends "
            "f_n = f_n^string (1 + 2/xi + (4 + n^2 pi^2 / 2) / xi^2), xi = l sqrt(T/EI) (large-xi expansion); "
            "stcs_ident.forward.reference.beam_pinned and beam_clamped_asymptotic",
    "zui1996": ZUI_SOURCE,
    "mehrabi1998": "Mehrabi, A. B., Tabatabai, H. (1998). Unified finite difference formulation for free vibration "
                   "of cables. J. Struct. Eng. (ASCE) 124(11), 1313-1322.",
    "exact": "exact dynamic stiffness of a tensioned, sagging beam (docs/model.md), solved for the tension: a "
             "bracketed root with one mode, least squares from a scan with more (stcs_ident.identify.quick_exact)",
}

#: Why ``mehrabi1998`` has no tension (the key stays in the JSON, as the contract has it; the text omits it).
UNSOURCED = "left out: no source of its coefficients could be read (not reconstructed from memory)"

#: With EI given, the taut string is left out (tension None) when its leading bias from bending exceeds this:
#: 4/ξ with clamped ends (ξ < 20), n²π²/ξ² with pinned ends.
TAUT_MAX_BIAS = 0.2

#: Irvine's λ² above which sag matters to the practical formulas (said in their note).
SAG_MATTERS = 0.3

#: The clamped-end expansion is used for a mode n when ξ ≥ max(CLAMPED_MIN_XI, CLAMPED_XI_PER_MODE · n):
#: there its tension is within 1.5 % of the exact clamped beam's (tests/test_tension.py checks it).
CLAMPED_MIN_XI = 20.0
CLAMPED_XI_PER_MODE = 6.0


# ---- results ------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class MethodEstimate:
    """One method's tension.

    Attributes
    ----------
    name : str
        ``taut_string``, ``beam``, ``zui1996``, ``mehrabi1998`` or ``exact``.
    tension, uncertainty : float or None
        N and its 1σ; None when the method does not apply (``note`` says why).
    note : str or None
        Why the tension is None, or what to know about it.
    source : str
        Where the formula comes from.
    per_mode : tuple of float
        The formulas' estimate from each mode (N), NaN where a mode is outside the formula's range.
    extra : dict
        More, by method: ``EI``, ``EI_uncertainty``, ``EI_source`` (exact), ``scatter`` (N), ``formula``.
    failed : bool
        The computation failed (exact model); the command line then exits with status 1.
    """

    name: str
    tension: float | None
    uncertainty: float | None
    note: str | None
    source: str
    per_mode: tuple[float, ...] = ()
    extra: dict = field(default_factory=dict)
    failed: bool = False

    def to_dict(self) -> dict:
        out = {"tension": _num(self.tension), "uncertainty": _num(self.uncertainty)}
        if self.name == "exact":
            out["EI"] = _num(self.extra.get("EI"))
        if self.note:
            out["note"] = self.note
        out["source"] = self.source
        if self.per_mode:
            out["per_mode"] = [_num(t) for t in self.per_mode]
        out.update({k: _num(v) if isinstance(v, float) else v for k, v in self.extra.items() if k != "EI"})
        return out


@dataclass(frozen=True, repr=False)
class QuickTensionResult(Result):
    """The tension by each method, side by side (:func:`quick_tension`).

    Attributes
    ----------
    inputs : dict
        What was given, in SI units (inclination in degrees), with the frequency σ used and its source.
    methods : dict of str to MethodEstimate
        In the order ``taut_string``, ``beam``, ``zui1996``, ``mehrabi1998``, ``exact``.
    notes : tuple of Note
    """

    inputs: dict
    methods: dict
    notes: tuple[Note, ...] = ()

    main_table = "methods"

    @property
    def settings(self):
        return None

    def tension(self, method: str = "exact") -> tuple[float | None, float | None]:
        """(tension N, 1σ N) of ``method``."""
        m = self.methods[method]
        return m.tension, m.uncertainty

    def summary(self) -> dict:
        """``{"inputs": {...}, "methods": {name: {"tension", "uncertainty", ...}}}`` (docs/formats.md)."""
        return {"inputs": dict(self.inputs), "methods": {k: m.to_dict() for k, m in self.methods.items()},
                "notes": [str(n) for n in self.notes]}

    to_dict = summary

    def tables(self):
        import pandas as pd

        rows = [{"method": k, "tension_N": m.tension, "uncertainty_N": m.uncertainty, "note": m.note or ""}
                for k, m in self.methods.items()]
        return {"methods": pd.DataFrame(rows, columns=["method", "tension_N", "uncertainty_N", "note"])}

    def headline(self) -> str:
        from ..core.formatting import plus_minus

        shown = [f"{k} {plus_minus(m.tension, m.uncertainty, 'N')}" for k, m in self.methods.items()
                 if m.tension is not None and m.uncertainty is not None]
        exact = self.methods["exact"]
        if exact.tension is None and exact.extra.get("upper") is not None:
            shown.append(f"exact between {plus_minus(exact.extra['lower'], None, 'N', digits=4)} and "
                         f"{plus_minus(exact.extra['upper'], None, 'N', digits=4)}")
        k = len(self.inputs["frequencies"])
        return f"{k} frequenc{'ies' if k != 1 else 'y'}; " + "; ".join(shown)


def _num(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


# ---- the quick answer ---------------------------------------------------------------------------------------

def rounding_uncertainty(texts: Sequence[str]) -> tuple[float, str]:
    """σ of frequencies as printed (``"1.230"`` has 3 decimals): the step / √12, and its description."""
    decimals = 0
    for text in texts:
        text = text.strip().lower()
        mantissa, _, exponent = text.partition("e")
        digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
        decimals = max(decimals, digits - (int(exponent) if exponent else 0))
    step = 10.0 ** (-decimals)
    return step / math.sqrt(12), f"rounding of the printed frequencies ({step:g} Hz / sqrt 12)"


def _check(length, mass, frequencies, modes, EI, EA, inclination, boundary, uncertainty):
    length = in_band(length, "length", "length")
    mass = in_band(mass, "mass", "mass_per_length")
    if isinstance(frequencies, (str, bytes)) or not isinstance(frequencies, Sequence | np.ndarray):
        raise InputError(f"must be a list of frequencies (Hz), got {frequencies!r}", field="frequencies")
    freqs = np.array([frequency(f, "frequencies") for f in frequencies])
    if freqs.size == 0:
        raise InputError("needs at least one frequency", field="frequencies")
    modes = np.arange(1, freqs.size + 1) if modes is None else np.array([mode_number(int(k) if isinstance(k, np.integer) else k, "modes") for k in modes])
    if modes.size != freqs.size:
        raise InputError(f"has {modes.size} mode numbers but there are {freqs.size} frequencies", field="modes")
    if np.unique(modes).size != modes.size:
        raise InputError("mode numbers must be distinct", field="modes")
    EI = None if EI is None else in_band(EI, "EI", "EI", zero=True)
    EA = None if EA is None else in_band(EA, "EA", "EA")
    inclination = finite_number(inclination, "inclination")
    if abs(inclination) > 90:
        raise InputError(f"must be between -90 and 90 degrees, got {inclination:g}", field="inclination")
    if boundary not in BOUNDARIES:
        raise InputError(f"must be one of {', '.join(BOUNDARIES)}, got {boundary!r}", field="boundary")
    if uncertainty is not None:
        u = np.atleast_1d(np.array([finite_number(x, "uncertainty") for x in np.atleast_1d(uncertainty)]))
        if u.size == 1:
            u = np.full(freqs.size, u[0])
        if u.size != freqs.size:
            raise InputError(f"has {u.size} values but there are {freqs.size} frequencies (give one for all, "
                             "or one per frequency)", field="uncertainty")
        if np.any(u <= 0) or np.any(u >= freqs):
            raise InputError("must be > 0 Hz and below its frequency", field="uncertainty")
        uncertainty = u
    order = np.argsort(modes)
    return (length, mass, freqs[order], modes[order], EI, EA, inclination, boundary,
            None if uncertainty is None else uncertainty[order])


def _mean(per_mode: np.ndarray, sigma: np.ndarray) -> tuple[float, float, float | None]:
    """Mean of the finite per-mode estimates, its σ (propagation ⊕ scatter / √k) and the scatter s."""
    ok = np.isfinite(per_mode)
    t, s = per_mode[ok], sigma[ok]
    k = t.size
    prop = math.sqrt(float(np.sum(s**2))) / k
    if k < 2:
        return float(t[0]), prop, None
    scatter = float(np.std(t, ddof=1))
    return float(np.mean(t)), math.sqrt(prop**2 + scatter**2 / k), scatter


def _taut(length, mass, freqs, modes, sigma, EI, boundary) -> MethodEstimate:
    per = taut_string_tension(length, mass, freqs, modes)
    t, u, scatter = _mean(per, 2 * per * sigma / freqs)
    extra = {"formula": "T = 4 m l^2 f_n^2 / n^2"}
    if scatter is not None:
        extra["scatter"] = scatter
    return MethodEstimate("taut_string", t, u, None, SOURCES["taut_string"], tuple(map(float, per)), extra)


def taut_bias(length, tension, EI, mode, boundary) -> float:
    """The taut string's relative excess in tension over a tensioned beam's, from the clamped-end expansion
    (T_string/T = (1 + 2/ξ + (4 + n²π²/2)/ξ²)²; leading term 4/ξ) or the pinned beam's exact n²π²/ξ²."""
    xi = length * math.sqrt(tension / EI)
    if boundary == "clamped":
        return (1 + 2 / xi + (4 + mode * mode * math.pi**2 / 2) / xi**2) ** 2 - 1
    return mode * mode * math.pi**2 / xi**2


def _taut_beside_exact(taut: MethodEstimate, exact: MethodEstimate, length, modes, EI, boundary) -> MethodEstimate:
    """The taut string's note, in the table's own numbers: its excess over the exact model's tension; left out
    (with EI given) when that excess is above :data:`TAUT_MAX_BIAS`."""
    if exact.tension is None and exact.extra.get("upper") is not None:
        return replace(taut, note="an upper bound: with EI unknown bending can only lower the tension (the exact "
                                  "model's range)")
    EI_used = exact.extra.get("EI") if exact.tension is not None else EI
    if not EI_used or taut.tension is None:
        return taut
    if exact.tension is not None and exact.tension > 0:
        bias, basis = taut.tension / exact.tension - 1, "above the exact model's tension"
        xi = length * math.sqrt(exact.tension / EI_used)
    else:  # no exact tension: the expansion at the taut string's own ξ (an underestimate of ξ's effect)
        bias = taut_bias(length, taut.tension, EI_used, float(modes[0]), boundary)
        basis, xi = "high from bending alone (by the tensioned beam's expansion)", length * math.sqrt(taut.tension / EI_used)
    extra = {**taut.extra, "xi": xi, "estimated_bias": bias}
    if EI and bias > TAUT_MAX_BIAS:
        return replace(taut, tension=None, uncertainty=None, extra=extra,
                       note=f"{100 * bias:.3g} % {basis}: bending dominates at xi = {xi:.3g} (limit "
                            f"{100 * TAUT_MAX_BIAS:g} %)")
    return replace(taut, extra=extra, note=f"ignores bending and sag: {100 * bias:.3g} % {basis} (xi = {xi:.3g})")


def _beam(length, mass, freqs, modes, sigma, EI, boundary) -> MethodEstimate:
    if not EI:
        return MethodEstimate("beam", None, None, "needs EI (--EI)", SOURCES["beam"])
    if boundary == "pinned":
        per = pinned_beam_tension(length, mass, freqs, modes, EI)
        per = np.where(per > 0, per, np.nan)
        dTdf = 8 * mass * length**2 * freqs / modes**2
        formula, why = "T = 4 m l^2 f_n^2 / n^2 - n^2 pi^2 EI / l^2 (pinned ends, exact)", "T <= 0"
    else:
        per, dTdf = np.full(freqs.size, np.nan), np.full(freqs.size, np.nan)
        for i, (f, n) in enumerate(zip(freqs, modes)):
            t = clamped_beam_tension(length, mass, f, int(n), EI)
            if math.isfinite(t) and length * math.sqrt(t / EI) >= max(CLAMPED_MIN_XI, CLAMPED_XI_PER_MODE * n):
                h = 1e-6 * t
                dfdT = (clamped_beam_frequency(length, mass, t + h, EI, int(n))
                        - clamped_beam_frequency(length, mass, t - h, EI, int(n))) / (2 * h)
                per[i], dTdf[i] = t, 1 / dfdT
        formula = "inverse of f_n = (n/2l) sqrt(T/m) (1 + 2/xi + (4 + n^2 pi^2/2)/xi^2) (clamped ends, large xi)"
        why = f"xi below max({CLAMPED_MIN_XI:g}, {CLAMPED_XI_PER_MODE:g} n)"
    if not np.any(np.isfinite(per)):
        return MethodEstimate("beam", None, None, f"outside the formula's range for every mode ({why})",
                              SOURCES["beam"], tuple(map(float, per)), {"formula": formula})
    t, u, scatter = _mean(per, np.abs(dTdf) * sigma)
    note = None
    if not np.all(np.isfinite(per)):
        note = f"modes {', '.join(str(int(n)) for n in modes[~np.isfinite(per)])} left out ({why})"
    extra = {"formula": formula, "xi": length * math.sqrt(t / EI)}
    if scatter is not None:
        extra["scatter"] = scatter
    return MethodEstimate("beam", t, u, note, SOURCES["beam"], tuple(map(float, per)), extra)


def _zui(length, mass, freqs, modes, sigma, EI, boundary) -> MethodEstimate:
    """Zui, Shinke & Namita (1996) per mode (:mod:`.zui`), averaged as the other formulas; its error band the
    largest of the modes' (measured against the exact model of a clamped cable without sag)."""
    if not EI:
        return MethodEstimate("zui1996", None, None, "needs EI (--EI)", SOURCES["zui1996"])
    if boundary != "clamped":
        return MethodEstimate("zui1996", None, None, "its formulas are for clamped ends", SOURCES["zui1996"])
    answers = [zui_tension(length, mass, float(f), int(n), EI) for f, n in zip(freqs, modes)]
    per = np.array([a.tension if a.ok else np.nan for a in answers])
    if not np.any(np.isfinite(per)):
        return MethodEstimate("zui1996", None, None, f"outside its rows: {answers[0].reason}", SOURCES["zui1996"],
                              tuple(map(float, per)))
    dTdf = np.array([a.dT_df if a.ok else np.nan for a in answers])
    t, u, scatter = _mean(per, np.abs(dTdf) * sigma)
    used = [(int(n), a) for n, a in zip(modes, answers) if a.ok]
    band = max(a.error_band for _, a in used)
    rows = "; ".join(f"mode {n}: row '{a.row}' at xi = {a.xi:.3g}" for n, a in used)
    left = [f"mode {int(n)} ({a.reason})" for n, a in zip(modes, answers) if not a.ok]
    note = (f"{rows}; error band ±{100 * band:.2g} % (measured against the exact model, clamped ends, no sag)"
            + (f"; left out: {', '.join(left)}" if left else ""))
    extra = {"formula": "Zui, Shinke & Namita (1996), the row of each mode's xi", "rows": [a.row for _, a in used],
             "xi": [a.xi for _, a in used], "error_band": band}
    if scatter is not None:
        extra["scatter"] = scatter
    return MethodEstimate("zui1996", t, u, note, SOURCES["zui1996"], tuple(map(float, per)), extra)


def _with_tolerances(method, length, mass, freqs, modes, sigma, EI, boundary, tolerance) -> MethodEstimate:
    """A formula's estimate with the tolerances of the length, the mass and a given EI in its σ (first order, by
    the formula's own change for a relative step of each: docs/uncertainty.md)."""
    estimate = method(length, mass, freqs, modes, sigma, EI, boundary)
    if estimate.tension is None:
        return estimate
    step, shares = 1e-6, {}
    for key, value in (("length", length), ("mass_per_length", mass), ("EI", EI)):
        if not value or not tolerance[key]:
            continue
        moved = {"length": length, "mass_per_length": mass, "EI": EI}
        moved[key] = value * (1 + step)
        other = method(moved["length"], moved["mass_per_length"], freqs, modes, sigma, moved["EI"], boundary).tension
        if other is not None:
            shares[key] = abs(other - estimate.tension) / step * tolerance[key]
    if not shares:
        return estimate
    extra = {**estimate.extra, "uncertainty_from_tolerances": shares}
    return replace(estimate, uncertainty=math.hypot(estimate.uncertainty, *shares.values()), extra=extra)


def _exact(length, mass, freqs, modes, sigma, EI, EA, inclination, boundary, tolerance,
           plane: str = "in") -> MethodEstimate:
    """The exact model, solved without a nominal (:mod:`.quick_exact`)."""
    member = Member(length, mass, EA, inclination, boundary, plane)
    try:
        answer = exact_tension(member, freqs, sigma, modes, EI, tolerance)
    except (ComputationError, FloatingPointError, ArithmeticError) as err:
        return MethodEstimate("exact", None, None, f"the exact model's computation failed: {err}", SOURCES["exact"],
                              failed=True)
    if answer.failed:
        return MethodEstimate("exact", None, None, f"no tension: {answer.reason}", SOURCES["exact"], failed=True)
    extra = {"EI": answer.EI, "EI_uncertainty": answer.EI_uncertainty, "EI_source": answer.EI_source,
             **answer.extra}
    return MethodEstimate("exact", answer.tension, answer.uncertainty, "; ".join(answer.notes) or None,
                          SOURCES["exact"], (), extra)


def quick_tension(length: float, mass: float, frequencies: Sequence[float], modes: Sequence[int] | None = None,
                  EI: float | None = None, EA: float | None = None, inclination: float = 0.0,
                  boundary: str = "clamped", uncertainty: float | Sequence[float] | None = None, *,
                  uncertainty_source: str | None = None, EI_tolerance: float | None = None,
                  length_tolerance: float | None = None, mass_tolerance: float | None = None,
                  plane: str = "in") -> QuickTensionResult:
    """A cable's tension from its length, mass and measured frequencies, by several methods side by side.

    Parameters
    ----------
    length : float
        Chord length between the anchorages, m.
    mass : float
        Mass per unit length, kg/m.
    frequencies : sequence of float
        Measured natural frequencies, Hz.
    modes : sequence of int, optional
        Their mode numbers (default 1, 2, ...).
    EI : float, optional
        Bending stiffness, N m², known to ``EI_tolerance``. Given: with one mode the exact model solves for
        the tension with EI held; with two modes or more it fits EI too, the given value its prior. Not given:
        fitted with two modes or more; with one mode the answer is a range.
    EA : float, optional
        Axial stiffness, N (sag-extensibility in the exact model); None ignores it.
    inclination : float
        Chord angle from horizontal, degrees.
    boundary : {"clamped", "pinned"}
        Both anchorages.
    uncertainty : float or sequence of float, optional
        1σ of the frequencies, Hz (one for all or one each). Default: the rounding of the frequencies as
        printed (step / √12).
    uncertainty_source : str, optional
        How ``uncertainty`` was obtained, recorded in ``inputs`` (the command line says "rounding of the
        printed frequencies" when it derived it from the typed text).
    EI_tolerance, length_tolerance, mass_tolerance : float, optional
        Relative 1σ of a given EI, of the length and of the mass per length (default: a campaign's defaults,
        30 %, 0.2 % and 1 %). Every method's σ includes them where the value is held fixed
        (docs/uncertainty.md); 0 says exact.
    plane : {"in", "out"}
        The plane the frequencies were measured in: the exact model fits the in-plane family (with
        sag-extensibility when EA is given) or the out-of-plane one (no sag-extensibility, EA unused).

    Returns
    -------
    QuickTensionResult
        ``.methods[name].tension`` / ``.uncertainty`` (N), ``.summary()`` (= ``.to_dict()``) the JSON of
        ``stcs-ident tension``.

    Raises
    ------
    InputError
        Naming the argument (``length``, ``mass``, ``frequencies``, ``modes``, ``EI``, ``EA``,
        ``inclination``, ``boundary``, ``uncertainty``, ``plane``).
    """
    if plane not in PLANES:
        raise InputError(f'must be "in" or "out", got {plane!r}', field="plane")
    length, mass, freqs, modes, EI, EA, inclination, boundary, sigma = _check(
        length, mass, frequencies, modes, EI, EA, inclination, boundary, uncertainty)
    if sigma is None:
        step = printed_step(freqs)
        sigma = np.full(freqs.size, step / math.sqrt(12))
        uncertainty_source = uncertainty_source or f"rounding of the frequencies as printed ({step:g} Hz / sqrt 12)"
        if np.any(sigma >= freqs):
            raise InputError("the rounding of the frequencies is as large as a frequency: give --uncertainty",
                             field="uncertainty")
    tolerance = {}
    for key, value in (("EI", EI_tolerance), ("length", length_tolerance), ("mass_per_length", mass_tolerance)):
        if value is not None:
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise InputError(f"must be a finite number >= 0, got {value!r}", field=f"{key}_tolerance")
            tolerance[key] = float(value)
    inputs = {"length": length, "mass": mass, "frequencies": freqs.tolist(), "modes": modes.tolist(), "EI": EI,
              "EA": EA, "inclination": inclination, "boundary": boundary, "uncertainty": sigma.tolist(),
              "uncertainty_source": uncertainty_source or "stated", "tolerance": tolerance, "plane": plane}
    held = {key: tolerance.get(key, kinds.get(key).tolerance.default) for key in ("length", "mass_per_length", "EI")}
    taut = _with_tolerances(_taut, length, mass, freqs, modes, sigma, EI, boundary, held)
    exact = _exact(length, mass, freqs, modes, sigma, EI, EA, inclination, boundary, held, plane)
    zui = _with_tolerances(_zui, length, mass, freqs, modes, sigma, EI, boundary, held)
    if zui.tension is not None and EA is not None and plane == "in":
        # the paper's sag criterion (its Γ) could not be verified: where Irvine's λ² says sag matters, say so
        lambda2 = irvine_lambda2(Member(length, mass, EA, inclination, boundary, plane).cable(), zui.tension)
        if lambda2 > SAG_MATTERS:
            zui = replace(zui, note=f"{zui.note}; sag matters here (Irvine's lambda^2 = {lambda2:.3g}) and the "
                                    "formulas' own sag criterion is not applied", extra={**zui.extra, "lambda2": lambda2})
    methods = {
        "taut_string": _taut_beside_exact(taut, exact, length, modes, EI, boundary),
        "beam": _with_tolerances(_beam, length, mass, freqs, modes, sigma, EI, boundary, held),
        "zui1996": zui,
        "mehrabi1998": MethodEstimate("mehrabi1998", None, None, UNSOURCED, SOURCES["mehrabi1998"]),
        "exact": exact,
    }
    return QuickTensionResult(inputs, methods)
