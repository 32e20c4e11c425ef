"""The identification problem: measured frequencies, their uncertainties and the model.

:class:`~stcs_ident.identify.measurement.Measurement` (:mod:`.measurement`, re-exported here) holds one
test's measured modes with a standard uncertainty and a plane per mode.

:class:`Problem` ties measurements and free parameters to the forward
solver. :meth:`Problem.predict` evaluates the model at many parameter
vectors in one vectorised call per setup (undamped: per topology, the setups
alike in one batch, what a call does not change worked out once per problem):
the residuals, the Jacobian, the multi-start scan and the contour grids all
go through it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..core import kinds
from ..core.errors import ComputationError, InputError, ModelError
from ..core.memo import BoundedCache, model_key
from ..core.model import Campaign, has_dampers
from ..core.parameters import Parameter, overrides_for
from ..core.planes import PLANES
from ..forward.damped import batch_complex_modes
from ..forward.dsm import PreparedModel, solve_parts
from .group_plan import MIN_GAP, GroupPlan, dashpots_on, valid_rows  # noqa: F401 (MIN_GAP re-exported)
from .measurement import (  # noqa: F401 (re-exported: the measurements' home before the planes)
    Measurement,
    as_measurement,
    gather_measurements,
    mode_label,
    picked_planes,
    printed_step,
    table_measurement,
)

#: Relative step of the numerical Jacobian (the solver is accurate to 1e-12).
JACOBIAN_STEP = 1e-6
#: Whether the trial points of a fit certify the count of their complex modes. Off: a fit evaluates
#: thousands of nearby configurations, each mode followed from its certified undamped root (a lost path
#: makes the row NaN, a point the fit avoids), and the count costs 40-70 % more per point; forward,
#: spectra's numbering and the reports certify. A batch whose every row the uncertified solve loses is solved
#: again certified (the count searches for the lost root): a 120 m stay's mode 21 beside a damper ten times its
#: optimum (campaigns/damped-stay) was lost at every tension, and a 60-s record that numbered it got no tension.
FIT_CERTIFY = False
#: Spread (absolute) of a cable's own damping ratio across modes, added in quadrature to a measured
#: damping ratio's σ: the model holds the dampers' damping and one own ratio for all modes (a nuisance
#: profiled out), while a cable's own damping varies from mode to mode by a few 1e-4 (aerodynamic
#: damping ∝ 1/f, friction at the anchorages).
DAMPING_SPREAD = 3e-4


class Problem:
    """Measurements, free parameters and the forward model, evaluated in batches.

    Parameters
    ----------
    campaign : Campaign
    measurements : list of Measurement
    parameters : sequence of Parameter
    tension_model : {"uniform", "per-segment", "none"}
    use_damping : bool, optional
        Whether measured damping ratios are data (default: with a damper in the model and a ratio measured).
    nuisance : sequence of Nuisance, optional
        Parameters held fixed whose tolerances go into the uncertainty of the estimate
        (:mod:`.nuisance`); default none.
    check : bool
        Whether to refuse fewer data than parameters (off for the Jacobian of the nuisances).

    Raises
    ------
    InputError
        ``field="params"`` when there are fewer measured frequencies than
        free parameters, or a parameter touches none of the tests.
    """

    def __init__(self, campaign: Campaign, measurements: Sequence[Measurement], parameters: Sequence[Parameter],
                 tension_model: str = "uniform", use_damping: bool | None = None, nuisance: Sequence = (),
                 check: bool = True):
        self.campaign = campaign
        self.measurements = list(measurements)
        self.parameters = tuple(parameters)
        self.tension_model = tension_model
        #: Parameters held fixed with their tolerances (:class:`~stcs_ident.identify.nuisance.Nuisance`).
        self.nuisance = tuple(nuisance)
        damped = any(has_dampers(campaign.setup(m.test.setup).attachments) for m in self.measurements)
        decided = {m.damping_is_data for m in self.measurements} - {None}
        if use_damping is None and decided:
            use_damping = True in decided
        measured = any(m.damping_used.any() for m in self.measurements)
        #: Whether measured damping ratios are data (default: with a damper in the model and a ratio measured).
        self.use_damping = (damped and measured) if use_damping is None else bool(use_damping and measured)
        self._zeta_used = [m.damping_used if self.use_damping else np.zeros(m.modes.size, bool)
                           for m in self.measurements]
        self.n_frequencies = int(sum(m.modes.size for m in self.measurements))
        n, p = self.n_data, len(self.parameters)
        if p == 0:
            raise InputError("no free parameter", field="params")
        if check and n < p:
            names = ", ".join(q.name for q in self.parameters)
            raise InputError(f"{p} free parameters ({names}) but only {n} measured frequencies", field="params")
        for q in self.parameters:
            if not any(q.applies_to(m.test) for m in self.measurements):
                raise InputError(f"{q.name} belongs to none of the selected tests", field="params")
        self._atts = {m.name: campaign.setup(m.test.setup).attachments for m in self.measurements}
        self._nominal_atts = {
            name: {k.override: np.array([getattr(a, k.attribute, 0.0) for a in atts], float)
                   for k in kinds.kinds() if k.belongs_to == "attachment"}
            for name, atts in self._atts.items()
        }
        groups: dict[str, list[int]] = {}
        for i, m in enumerate(self.measurements):
            groups.setdefault(m.test.setup, []).append(i)
        self._groups = list(groups.values())
        self.measured = np.concatenate([m.frequencies for m in self.measurements]
                                       + [m.damping[u] for m, u in zip(self.measurements, self._zeta_used) if u.any()])
        self.sigma = np.concatenate([m.uncertainty for m in self.measurements]
                                    + [np.hypot(m.damping_uncertainty[u], DAMPING_SPREAD)
                                       for m, u in zip(self.measurements, self._zeta_used) if u.any()])
        self.lower = np.array([q.lower for q in self.parameters])
        self.upper = np.array([q.upper for q in self.parameters])
        self.start = np.array([q.start for q in self.parameters])
        self._plans: list | None = None  # the undamped path's per-setup plans (_group_plans), on first use
        self._solvers: dict = {}  # a PreparedModel per (setup's attachments, plane): _solver

    @property
    def n_data(self) -> int:
        """Frequencies, and the damping ratios when they are data."""
        return self.n_frequencies + int(sum(u.sum() for u in self._zeta_used))

    @property
    def names(self) -> list[str]:
        return [q.name for q in self.parameters]

    def predict(self, X) -> np.ndarray:
        """Model frequencies of every measured mode at the variable rows ``X``.

        Parameters
        ----------
        X : array of shape (k, p) or (p,)

        Returns
        -------
        ndarray of shape (k, n_data) (or (n_data,)), Hz, tests in order and
        modes as measured; NaN for a row the model cannot take (two
        attachments at one place, an attachment outside the span).
        """
        X = np.asarray(X, float)
        single = X.ndim == 1
        X = np.atleast_2d(X)
        k = X.shape[0]
        if self._pure():  # the undamped path: each setup's overrides as planned once, setups alike solved together
            F = np.full((k, self.n_frequencies), np.nan)
            together: dict = {}
            for plan in self._plans:
                plan.fill(self, X, F, together)
            for entries in together.values():
                try:
                    fulls = solve_parts([e[0] for e in entries], [e[1] for e in entries])
                except ComputationError:  # each apart, as _solve solves it (row by row where a row fails)
                    fulls = [self._solve(plan.atts, tension, n_modes, sub, False, plane)[0]
                             for _, n_modes, plan, plane, tension, sub, _ in entries]
                for (_, n_modes, plan, _, _, _, where), full in zip(entries, fulls):
                    plan.scatter(F, full, n_modes, *where)
            return F[0] if single else F
        cable = self.campaign.cable
        out = [np.full((k, m.modes.size), np.nan) for m in self.measurements]
        zeta = [np.full((k, int(u.sum())), np.nan) for u in self._zeta_used]
        # One solver call per setup: the tests of a setup differ only in their overrides' values.
        for group in self._groups:
            first = self.measurements[group[0]]
            ovs = [overrides_for(self.measurements[i].test, self.parameters, X, len(self._atts[first.name]),
                                 self._nominal_atts[first.name]) for i in group]
            ov = {key: np.concatenate([o[key] for o in ovs]) for key in ovs[0]}
            ok = valid_rows(ov, cable.length, self._nominal_atts[first.name]["positions"])
            if not ok.any():
                continue
            sub = {key: v[ok] for key, v in ov.items()}
            tension = sub.pop("tension")
            for plane in PLANES:  # each plane's modes from its own model (out-of-plane: no sag-extensibility)
                members = [i for i in group if np.any(self.measurements[i].planes == plane)]
                if members:
                    self._predict_plane(plane, group, members, k, ok, tension, sub, out, zeta)
        F = np.concatenate(out + [z for z in zeta if z.shape[1]], axis=1)
        if self.n_data > self.n_frequencies:
            F[:, self.n_frequencies:] += self._own_damping(F[:, self.n_frequencies:])
        return F[0] if single else F

    def _predict_plane(self, plane: str, group: list[int], members: list[int], k: int, ok: np.ndarray,
                       tension: np.ndarray, sub: dict, out: list, zeta: list) -> None:
        """Fill ``out`` and ``zeta`` (in place) for the modes in ``plane`` of the measurements ``members`` of one
        setup's ``group`` (rows ``ok`` of the group's stacked overrides ``sub``)."""
        first = self.measurements[group[0]]
        n_modes = max(int(self.measurements[i].modes[self.measurements[i].planes == plane].max()) for i in members)
        damped = self.use_damping and any((self._zeta_used[i] & (self.measurements[i].planes == plane)).any()
                                          for i in members)
        try:
            F, Z = self._solve(self._atts[first.name], tension, n_modes, sub, damped, plane)
        except ModelError as err:
            raise InputError(f"the model refused a parameter value: {err.message}", field=err.field) from err
        full = np.full((ok.size, n_modes), np.nan)
        full[ok] = F
        if damped:
            full_zeta = np.full((ok.size, n_modes), np.nan)
            full_zeta[ok] = Z
        for j, i in enumerate(group):
            if i not in members:
                continue
            m, used = self.measurements[i], self._zeta_used[i]
            here = m.planes == plane
            out[i][:, here] = full[j * k:(j + 1) * k, m.modes[here] - 1]
            if damped and (used & here).any():
                zeta[i][:, here[used]] = full_zeta[j * k:(j + 1) * k, m.modes[used & here] - 1]

    def damping_columns(self, before: np.ndarray, after: np.ndarray) -> list[dict[str, np.ndarray]]:
        """Per measurement, the measured damping ratios, their σ and the model's ``before`` and ``after`` (two
        :meth:`predict` rows), by mode, NaN where not measured; empty dicts when damping is not data."""
        out, k = [], self.n_frequencies
        for m, used in zip(self.measurements, self._zeta_used):
            if not self.use_damping:
                out.append({})
                continue
            columns = {"measured": np.where(used, m.damping, np.nan), "uncertainty": np.where(used, m.damping_uncertainty,
                                                                                             np.nan)}
            for key, row in (("before", before), ("after", after)):
                columns[key] = np.full(m.modes.size, np.nan)
                columns[key][used] = row[k:k + int(used.sum())]
            k += int(used.sum())
            out.append(columns)
        return out

    def _own_damping(self, model: np.ndarray) -> np.ndarray:
        """The cable's own damping ratio per row, (k, 1): the weighted mean of measured − model damping ratios
        (≥ 0), profiled out as a linear nuisance (the model's ratios are the dampers' alone)."""
        measured = self.measured[self.n_frequencies:]
        w = self.sigma[self.n_frequencies:] ** -2
        own = np.sum(w * (measured - model), axis=1, keepdims=True) / np.sum(w)
        return np.maximum(own, 0.0)

    def _solve(self, atts, tension: np.ndarray, n_modes: int, overrides: dict,
               damped: bool = False, plane: str = "in") -> tuple[np.ndarray, np.ndarray | None]:
        """Frequencies (and, when ``damped``, damping ratios) in ``plane`` on many rows; a row whose roots do not
        converge (an extreme trial point of a fit) becomes NaN instead of failing the whole batch."""
        cable = self.campaign.cable
        try:
            if damped or dashpots_on(atts, overrides):  # the fit's trial points: uncertified (see FIT_CERTIFY)
                # Warm-started from the last row solved: a fit's next trial point, or a Jacobian's steps, moves
                # each root by a small part of its spacing (forward.damped._warm checks that, else solves cold).
                # The start is scaled by √(H / H_last): the tension moves every root about so.
                key = model_key(cable, tuple(atts), plane, n_modes, self.tension_model)
                point = None if key is None or tension.size != 1 else _point(key, tension, overrides)
                known = _SOLVED.get(point)
                if known is not None:
                    return np.abs(known) / (2 * math.pi), (-known.real / np.abs(known)) if damped else None
                any_setup = model_key(cable, plane, n_modes, self.tension_model)
                last = _LAST_ROOTS.get(key, _LAST_ROOTS.get(any_setup))  # else another setup's, if any
                start = None if last is None else _nearest_start(last, tension)
                s = batch_complex_modes(cable, atts, tension, n_modes, tension_model=self.tension_model,
                                        certify=FIT_CERTIFY, plane=plane, start=start, lost="nan", **overrides)
                if not FIT_CERTIFY and not np.isfinite(s).all(axis=1).any():
                    # Every row lost: the uncertified solve cannot follow some mode of this model at all (not an
                    # extreme trial point, which the fit steps back from): solved again certified (the count
                    # searches for the lost root). Rows lost beside found ones stay NaN: retrying those made a
                    # diagnosis of a damped stay 3-4 times slower.
                    s = batch_complex_modes(cable, atts, tension, n_modes, tension_model=self.tension_model,
                                            certify=True, plane=plane, lost="nan", **overrides)
                solved = np.all(np.isfinite(s), axis=1) & np.all(s.imag > 0, axis=1)
                if solved.any():
                    kept = (np.broadcast_to(np.ravel(tension), solved.shape)[solved].copy(), s[solved].copy())
                    for k in (key, any_setup):
                        _LAST_ROOTS.put(k, kept)
                    _SOLVED.put(point, s.copy())
                return np.abs(s) / (2 * math.pi), (-s.real / np.abs(s)) if damped else None
            return self._solver(atts, plane)(tension, n_modes, overrides), None
        except ComputationError:
            if tension.size == 1:
                return np.full((1, n_modes), np.nan), np.full((1, n_modes), np.nan) if damped else None
        rows = [self._solve(atts, tension[i:i + 1], n_modes, {k: v[i:i + 1] for k, v in overrides.items()}, damped,
                            plane)
                for i in range(tension.size)]
        return np.concatenate([r[0] for r in rows]), np.concatenate([r[1] for r in rows]) if damped else None

    def _pure(self) -> bool:
        """Whether each row of :meth:`predict` depends on that row alone (the undamped path): then a row solved
        alone or in any batch gives the same frequencies, bit for bit."""
        if self.use_damping:
            return False
        if self._plans is None:
            self._plans = [GroupPlan(self, group) for group in self._groups]
        return all(plan.usable for plan in self._plans)

    def _solver(self, atts, plane: str) -> PreparedModel:
        """The undamped solver of a setup's attachments ``atts`` (one of this problem's) in ``plane``."""
        solver = self._solvers.get((id(atts), plane))
        if solver is None:
            solver = self._solvers[id(atts), plane] = PreparedModel(self.campaign.cable, atts,
                                                                    tension_model=self.tension_model, plane=plane)
        return solver

    def residuals(self, x) -> np.ndarray:
        """Weighted residuals (f_model − f_measured) / σ at one parameter vector."""
        return (self.predict(x) - self.measured) / self.sigma

    def typical(self, x) -> np.ndarray:
        """The size of each variable at ``x`` that its Jacobian step is a fraction of: |x|, at least 1 (1 for
        an end fixity). A column times it is the data's change for a relative change of the variable, which
        compares across variables of different units (a tension ratio, a stiffness in N/m)."""
        x = np.asarray(x, float)
        size = np.maximum(np.abs(x), 1.0)
        return np.where([q.is_fixity for q in self.parameters], 1.0, size)

    def jacobian(self, x) -> np.ndarray:
        """d residuals / d variables by central differences (one-sided at a bound), one batch."""
        x = np.asarray(x, float)
        p = x.size
        h = JACOBIAN_STEP * self.typical(x)
        up = np.minimum(x + h, self.upper)
        down = np.maximum(x - h, self.lower)
        # The point itself only where a step is lost, solved apart, when a row's frequencies depend on that row
        # alone (the undamped path; the damped one warm-starts from the rows of its last call).
        base = 0 if self._pure() else 1
        rows = np.repeat(x[None, :], 2 * p + base, axis=0)
        rows[np.arange(p), np.arange(p)] = up
        rows[p + np.arange(p), np.arange(p)] = down
        F = self.predict(rows)
        F_up, F_down = F[:p], F[p:2 * p]
        J = (F_up - F_down) / (up - down)[:, None]
        # A step the model cannot take (an attachment pushed onto another): one-sided from the other.
        lost_up, lost_down = ~np.isfinite(F_up), ~np.isfinite(F_down)
        if lost_up.any() or lost_down.any():
            F0 = F[2 * p] if base else self.predict(x)
            with np.errstate(invalid="ignore", divide="ignore"):
                forward = (F_up - F0) / (up - x)[:, None]
                backward = (F0 - F_down) / (x - down)[:, None]
            J = np.where(lost_up & ~lost_down, backward, np.where(lost_down & ~lost_up, forward, J))
        return J.T / self.sigma[:, None]

    def nuisance_jacobian(self, x) -> np.ndarray:
        """d residuals / d nuisance variables at the estimate ``x``, each column times the nuisance's width
        (n_data, q); empty (n_data, 0) without nuisances."""
        if not self.nuisance:
            return np.zeros((self.n_data, 0))
        extra = [n.parameter for n in self.nuisance]
        joint = Problem(self.campaign, self.measurements, self.parameters + tuple(extra), self.tension_model,
                        use_damping=self.use_damping, check=False)
        x_joint = np.concatenate([np.asarray(x, float), [q.start for q in extra]])
        J = joint.jacobian(x_joint)[:, len(self.parameters):]
        return J * np.array([n.width for n in self.nuisance])

    def chi2(self, X) -> np.ndarray:
        """χ² at the rows of ``X`` (inf where the model is undefined)."""
        r = (self.predict(np.atleast_2d(X)) - self.measured) / self.sigma
        c = np.sum(r**2, axis=1)
        return np.where(np.isfinite(c), c, np.inf)


#: The tensions and complex roots of the last damped rows solved (one call's) per (cable, attachments, plane, modes,
#: tension model), in this process: the warm start of the next solve of that model (:meth:`Problem._solve`, each
#: row from the kept row of the nearest tension), whichever fit asks (a diagnosis's hypotheses and cross-validation
#: folds start near each other's points); and per model without its attachments, the start of a setup not solved
#: yet (a hypothesis's added mass moves the roots a little; the warm start's checks refuse what moved too far). At
#: most this many.
MAX_WARM_STARTS = 64
_LAST_ROOTS = BoundedCache(MAX_WARM_STARTS)


#: The roots of the single points solved (a fit's start, which every cross-validation fold of a hypothesis
#: shares), by model and point, since the last :func:`reset_warm_starts`: each such point is solved once. With
#: pairs of effects on a damped stay, 2000 of a diagnosis's 16 600 solves, and a tenth of its time. At most
#: this many.
MAX_SOLVED = 4096
_SOLVED = BoundedCache(MAX_SOLVED)


def _point(key, tension: np.ndarray, overrides: dict) -> tuple:
    """The key of one parameter point of a model: its tension and every override's value, exactly."""
    values = tuple((name, np.asarray(v, float).tobytes()) for name, v in sorted(overrides.items()))
    return key, np.asarray(tension, float).tobytes(), values


def _nearest_start(last: tuple[np.ndarray, np.ndarray], tension: np.ndarray) -> np.ndarray:
    """The warm start of each row of ``tension``: the roots of the last call's row of the nearest tension, scaled
    by √(H / H_that) (the tension moves every root about so).

    One row kept per model made every row start from the last one: a setup's tests at 4.0 and 4.6 MN then
    started each other's roots, whose real parts (the damper's share of ζ changes with the tension) were off
    by up to 0.6 1/s, and the secant landed on the damper's real root or failed: a
    damped stay's diagnosis solved a sixth of its rows cold (6 ms each against 0.1 ms warm).
    """
    tensions, roots = last
    h = np.reshape(np.asarray(tension, float), (-1, 1))
    nearest = np.argmin(np.abs(np.log(h / tensions[None, :])), axis=1)
    return roots[nearest] * np.sqrt(h / tensions[nearest][:, None])


def reset_warm_starts() -> None:
    """Forget the roots kept for warm starts: a computation that begins here (an identification, one
    hypothesis of a diagnosis with its cross-validation) then depends on its own inputs only, not on what
    this process solved before (a warm start that succeeds where the cold solve of a trial point fails can
    lead a fit elsewhere; the fitted values agree to about 1e-9 where the fit is well posed)."""
    _LAST_ROOTS.clear()
    _SOLVED.clear()
