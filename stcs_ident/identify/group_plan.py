"""The bookkeeping of :meth:`Problem.predict <stcs_ident.identify.problem.Problem.predict>` worked out once per
setup (:class:`GroupPlan`), and the checks of a batch's rows it shares with the generic path (:func:`valid_rows`,
:func:`dashpots_on`)."""

from __future__ import annotations

import numpy as np

from ..core.errors import InputError, ModelError
from ..core.planes import PLANES

#: Closest two attachments of a trial row may come, as a fraction of the length (unless the nominal
#: configuration has a closer pair). Two nodes a gap g apart are joined by a segment whose stiffness
#: grows as EI/g³, and the frequencies lose about (l/g)³ × 1e-16 of their accuracy: measured 1e-9
#: relative at g = 1.25e-3 l on a hanger (ξ ≈ 11), 2e-4 at 1.25e-5 l, and a non-finite matrix at
#: 2e-10 l. At 1e-3 l (8 mm on an 8 m hanger) the model stays accurate to a few 1e-9.
MIN_GAP = 1e-3


class GroupPlan:
    """What :meth:`Problem.predict` works out per call for one setup's tests, worked out once (the undamped
    path): which parameter writes which override of which test, whether the rows can be invalid, and
    where each plane's frequencies go. :meth:`fill` then does what ``predict``'s generic loop does, with
    the same overrides and so the same frequencies, without repeating the bookkeeping."""

    def __init__(self, problem, group: list[int]):
        self.group = group
        ms = [problem.measurements[i] for i in group]
        self.atts = problem._atts[ms[0].name]
        self.n_attachments = len(self.atts)
        self.nominal = problem._nominal_atts[ms[0].name]
        self.tensions = [m.test.tension for m in ms]
        # (column, parameter, kind, attachment slot, scale: the value is the variable times it; None: to_value)
        self.writes = [[(j, q, q.spec, q.slot(m.test.setup), None if q.is_fixity else q.scale)
                        for j, q in enumerate(problem.parameters) if q.applies_to(m.test)] for m in ms]
        keys = []
        for writes in self.writes:
            here = ["tension"]
            for _, q, spec, _, _ in writes:
                if spec.belongs_to == "end":
                    here += ["end_a", "end_b"] if q.member == "AB" else ["end_a" if q.member == "A" else "end_b"]
                else:
                    here.append(spec.override)
            keys.append(list(dict.fromkeys(here)))
        self.keys = keys[0]
        # The generic path where the tests' overrides differ in kind, or a dashpot may be on.
        self.usable = all(set(k) == set(self.keys) for k in keys) and "coefficients" not in self.keys \
            and not dashpots_on(self.atts, {})
        self.always_valid = None
        if "positions" not in self.keys and "length" not in self.keys:  # every row alike: checked once
            self.always_valid = bool(valid_rows({"tension": np.ones(1)}, problem.campaign.cable.length,
                                                self.nominal["positions"])[0])
        offsets = np.cumsum([0] + [m.modes.size for m in problem.measurements])
        self.planes = []
        for plane in PLANES:
            members = [(j, i) for j, i in enumerate(group) if np.any(problem.measurements[i].planes == plane)]
            if not members:
                continue
            n_modes = max(int(problem.measurements[i].modes[problem.measurements[i].planes == plane].max())
                          for _, i in members)
            targets = []
            for j, i in members:
                m = problem.measurements[i]
                here = m.planes == plane
                targets.append((j, offsets[i] + np.flatnonzero(here), m.modes[here] - 1))
            self.planes.append((plane, n_modes, targets))

    def overrides(self, X: np.ndarray) -> dict[str, np.ndarray]:
        """The group's overrides at the rows ``X`` (k, p), its tests one after the other (as ``overrides_for``
        gives each test's, concatenated)."""
        k = X.shape[0]
        n = k * len(self.tensions)
        out: dict[str, np.ndarray] = {}
        for key in self.keys:
            out[key] = np.empty((n, self.n_attachments)) if key in self.nominal else np.empty(n)
        for t, (tension, writes) in enumerate(zip(self.tensions, self.writes)):
            rows = slice(t * k, (t + 1) * k)
            out["tension"][rows] = tension
            for key in self.keys:
                if key in self.nominal:
                    out[key][rows] = self.nominal[key]
            for j, q, spec, slot, scale in writes:
                value = q.to_value(X[:, j]) if scale is None else X[:, j] * scale  # to_value's product
                if spec.belongs_to == "end":
                    for end in ("end_a", "end_b") if q.member == "AB" else ("end_a" if q.member == "A" else "end_b",):
                        out[end][rows] = value
                elif spec.belongs_to == "attachment":
                    out[spec.override][rows, slot] = value
                else:
                    out[spec.override][rows] = value
        return out

    def fill(self, problem, X: np.ndarray, F: np.ndarray, together: dict) -> None:
        """Write the group's frequencies at the rows ``X`` into their columns of ``F`` (k, n_frequencies), or
        leave a plane's sets in ``together`` (by the key of the parts that can be solved as one batch: the
        entries (part, modes, this plan, plane, tension, overrides, where), for :meth:`scatter`)."""
        k = X.shape[0]
        ov = self.overrides(X)
        if self.always_valid is None:
            ok = valid_rows(ov, problem.campaign.cable.length, self.nominal["positions"])
            every = bool(ok.all())
            if not ok.any():
                return
        elif not self.always_valid:
            return
        else:
            every = True
        sub = ov if every else {key: v[ok] for key, v in ov.items()}
        tension = sub.pop("tension")
        for plane, n_modes, targets in self.planes:
            where = (targets, None if every else ok, k)
            part = problem._solver(self.atts, plane).part(tension, sub)
            if part is not None:
                together.setdefault(part[0], []).append((part, n_modes, self, plane, tension, sub, where))
                continue
            try:
                full, _ = problem._solve(self.atts, tension, n_modes, sub, False, plane)
            except ModelError as err:
                raise InputError(f"the model refused a parameter value: {err.message}", field=err.field) from err
            self.scatter(F, full, n_modes, *where)

    @staticmethod
    def scatter(F: np.ndarray, full: np.ndarray, n_modes: int, targets: list, ok: np.ndarray | None, k: int) -> None:
        """Write a plane's frequencies ``full`` of the group's valid rows (``ok``, None: all) into ``F``."""
        if ok is not None:
            every = np.full((ok.size, n_modes), np.nan)
            every[ok] = full
            full = every
        for j, columns, modes in targets:
            F[:, columns] = full[j * k:(j + 1) * k, modes]


def dashpots_on(atts, overrides) -> bool:
    """Whether a dashpot is on (a damper, or a ``coefficients`` override)."""
    if "coefficients" in overrides:
        return bool(np.any(np.asarray(overrides["coefficients"]) != 0))
    return any(getattr(a, "coefficient", 0.0) for a in atts)


def valid_rows(ov: dict[str, np.ndarray], length: float, nominal_positions: np.ndarray) -> np.ndarray:
    """Rows whose attachments lie strictly inside the span, at places at least :data:`MIN_GAP` of the
    length apart (or as close as the nominal configuration's closest pair, if that is closer)."""
    k = ov["tension"].shape[0]
    pos = ov.get("positions")
    if pos is None:
        pos = np.broadcast_to(nominal_positions, (k, nominal_positions.size))
    span = ov.get("length")
    ok = ((pos > 0) & (pos < (length if span is None else span[:, None]))).all(axis=1)
    if pos.shape[1] > 1:
        nominal_gap = np.min(np.diff(np.sort(nominal_positions)), initial=np.inf)
        gap = min(MIN_GAP * length, nominal_gap) if span is None else np.minimum(MIN_GAP * span, nominal_gap)[:, None]
        ordered = np.sort(pos, axis=1)
        step = ordered[:, 1:] - ordered[:, :-1]
        ok &= (step >= gap).all(axis=1) & (step > 0).all(axis=1)
    return ok
