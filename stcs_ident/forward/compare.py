"""The nominal model against measured and published frequencies (``forward``).

For every test: the exact DSM frequencies, the taut-string and pinned-beam
formulas, the measured frequencies and their errors in percent,
(computed − measured) / measured × 100. For reference columns (frequencies
computed by others, such as a paper's own model) the comparison says
whether the nominal model reproduces them and, where it does not, which
bending stiffness would.

Each plane of transverse motion is its own family of modes: in-plane (the
default) and out-of-plane (no sag-extensibility, springs at their
``stiffness_out``, dampers at sin²α; :mod:`stcs_ident.core.planes`). A
measured frequency is compared with the mode of its own plane
(``Test.planes``); mode numbers count per plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.optimize import minimize_scalar

from ..core.formatting import percent_error
from ..core.model import Campaign, Test, has_dampers
from ..core.planes import PLANE_NAMES, PLANES
from ..core.result import Result
from ..core.settings import Settings
from . import batch_frequencies
from . import reference as closed_form
from .damped import complex_modes


@dataclass(frozen=True)
class TestComparison:
    """One test's frequencies by every model, ordered by ``modes`` (Hz)."""

    __test__ = False

    name: str
    setup: str
    tension: float
    modes: tuple[int, ...]
    dsm: np.ndarray
    taut_string: np.ndarray
    beam_pinned: np.ndarray
    measured: np.ndarray | None
    reference: dict[str, np.ndarray] = field(default_factory=dict)
    damping: np.ndarray | None = None  # the DSM's damping ratios, with a damper (complex modes)
    plane: str = "in"  # the family of modes: "in" (in-plane) or "out" (out-of-plane)

    def error(self, column: str) -> np.ndarray | None:
        """(computed − measured) / measured × 100 for one model column."""
        if self.measured is None:
            return None
        return percent_error(getattr(self, column), self.measured)

    def to_dataframe(self) -> pd.DataFrame:
        """One row per mode: ``measured_Hz`` (where measured), ``taut_string_Hz``, ``beam_pinned_Hz``, ``dsm_Hz``
        each with its ``<model>_error_percent`` where measured, ``dsm_damping_ratio`` with a damper, and each
        reference column as ``<label>_Hz``."""
        data = {"mode": list(self.modes)}
        if self.measured is not None:
            data["measured_Hz"] = self.measured
        for col in ("taut_string", "beam_pinned", "dsm"):
            data[f"{col}_Hz"] = getattr(self, col)
            if self.measured is not None:
                data[f"{col}_error_percent"] = self.error(col)
        if self.damping is not None:
            data["dsm_damping_ratio"] = self.damping
        for label, values in self.reference.items():
            data[f"{label}_Hz"] = values
        return pd.DataFrame(data)


@dataclass(frozen=True)
class ReferenceCheck:
    """Does the nominal model reproduce a reference column of some tests?

    Attributes
    ----------
    label, setup : the reference column and the setup of its tests
    tests : names of the tests compared
    step : the column's printed resolution (Hz), the tolerance of "reproduces"
    rms_nominal, max_nominal, worst_mode : difference with the nominal EI (Hz)
    EI_nominal, EI_best : nominal EI and the EI that reproduces it best (N m²)
    rms_best : rms difference with EI_best (Hz)
    """

    label: str
    setup: str
    tests: tuple[str, ...]
    step: float
    rms_nominal: float
    max_nominal: float
    worst_mode: int
    EI_nominal: float
    EI_best: float
    rms_best: float

    @property
    def reproduced(self) -> bool:
        return self.max_nominal <= self.step

    def sentence(self) -> str:
        tests = ", ".join(self.tests)
        if self.reproduced:
            return (f"The nominal model (EI = {self.EI_nominal / 1e3:.1f} kN m²) reproduces '{self.label}' of "
                    f"{tests} within its printed resolution ({self.step:g} Hz): rms {self.rms_nominal:.3f} Hz.")
        head = (f"The nominal EI = {self.EI_nominal / 1e3:.1f} kN m² does NOT reproduce '{self.label}' of {tests}: "
                f"rms difference {self.rms_nominal:.3f} Hz, largest {self.max_nominal:.2f} Hz (mode "
                f"{self.worst_mode}); ")
        if self.rms_best <= self.step:
            return head + f"EI = {self.EI_best / 1e3:.1f} kN m² reproduces it to rms {self.rms_best:.4f} Hz."
        return head + (f"no single EI does (the best, {self.EI_best / 1e3:.1f} kN m², still leaves rms "
                       f"{self.rms_best:.3f} Hz), so it differs from this model in more than EI.")


@dataclass(frozen=True, repr=False)
class ForwardResult(Result):
    """Result of :func:`compare_forward`: one :class:`TestComparison` per test
    and plane and one :class:`ReferenceCheck` per (reference column, setup),
    with the :class:`~stcs_ident.core.settings.Settings` they were computed
    with.

    ``tests`` holds the in-plane family (empty when only the out-of-plane one
    was asked for), ``out_of_plane`` the out-of-plane one (empty unless asked
    for); ``planes`` names the families computed. ``tables()`` holds
    ``frequencies`` (one row per test and mode, the main table; a ``plane``
    column when out-of-plane modes are in it) and ``reference_checks``;
    ``notes`` is empty (the comparison has nothing to remark beyond its
    checks).
    """

    campaign: str
    settings: Settings
    tests: list[TestComparison]
    reference_checks: list[ReferenceCheck]
    notes: tuple = ()
    out_of_plane: list[TestComparison] = field(default_factory=list)
    planes: tuple[str, ...] = ("in",)

    main_table = "frequencies"

    @property
    def tension_model(self) -> str:
        return self.settings.tension_model

    @property
    def comparisons(self) -> list[TestComparison]:
        """Every test's comparison, per test in-plane then out-of-plane."""
        out = {t.name: t for t in self.out_of_plane}
        both = [c for t in self.tests for c in (t, out.pop(t.name, None)) if c is not None]
        return both + list(out.values())

    def test(self, name: str, plane: str = "in") -> TestComparison:
        """The comparison of the test called ``name`` in ``plane`` ("in" or "out")."""
        family = self.out_of_plane if plane == "out" else self.tests
        for t in family:
            if t.name == name:
                return t
        raise KeyError(f"no {PLANE_NAMES.get(plane, plane)} comparison of a test named {name!r} "
                       f"(known: {', '.join(t.name for t in family)})")

    def tables(self) -> dict[str, pd.DataFrame]:
        """``frequencies``: per test and mode, every model (Hz) and its error (%) where measured;
        ``reference_checks``: one row per reference column and setup."""
        frames = []
        for t in self.comparisons:
            frame = t.to_dataframe()
            if self.out_of_plane:
                frame.insert(0, "plane", t.plane)
            frame.insert(0, "test", t.name)
            frames.append(frame)
        frequencies = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame({"test": [], "mode": []})
        checks = pd.DataFrame(
            [{"label": c.label, "setup": c.setup, "tests": ";".join(c.tests), "reproduced": c.reproduced,
              "step_Hz": c.step, "rms_nominal_Hz": c.rms_nominal, "max_nominal_Hz": c.max_nominal,
              "worst_mode": c.worst_mode, "EI_nominal_Nm2": c.EI_nominal, "EI_best_Nm2": c.EI_best,
              "rms_best_Hz": c.rms_best} for c in self.reference_checks],
            columns=["label", "setup", "tests", "reproduced", "step_Hz", "rms_nominal_Hz", "max_nominal_Hz",
                     "worst_mode", "EI_nominal_Nm2", "EI_best_Nm2", "rms_best_Hz"])
        return {"frequencies": frequencies, "reference_checks": checks}

    def headline(self) -> str:
        """Campaign, tests, and the DSM's rms error against the measured frequencies."""
        every = self.comparisons
        errors = [e for t in every if t.measured is not None for e in t.error("dsm") if np.isfinite(e)]
        rms = f"; DSM rms error {math.sqrt(np.mean(np.square(errors))):.3g} %" if errors else ""
        modes = sum(len(t.modes) for t in every)
        count = len({t.name for t in every})
        planes = "" if self.planes == ("in",) else f", {' and '.join(PLANE_NAMES[p] for p in self.planes)}"
        return (f"{self.campaign}, {count} test{'s' if count != 1 else ''}, {modes} modes{planes} "
                f"({self.tension_model} tension model){rms}")

    def summary(self) -> dict:
        """Plain data for JSON (the ``forward`` object, with ``reference`` and ``settings`` keys)."""
        def floats(a):
            return None if a is None else [None if math.isnan(x) else float(x) for x in a]

        def family(t):
            return {"modes": list(t.modes),
                    "frequencies": {"dsm": floats(t.dsm), "taut_string": floats(t.taut_string),
                                    "beam_pinned": floats(t.beam_pinned)},
                    "measured": floats(t.measured),
                    "errors": None if t.measured is None else
                    {c: floats(t.error(c)) for c in ("dsm", "taut_string", "beam_pinned")},
                    "reference": {k: floats(v) for k, v in t.reference.items()},
                    **({} if t.damping is None else {"damping": {"dsm": floats(t.damping)}})}

        entries: dict[str, dict] = {}  # per test: the in-plane family's keys, the other under "out_of_plane"
        for t in self.comparisons:
            entry = entries.setdefault(t.name, {"name": t.name, "setup": t.setup, "tension": t.tension})
            if t.plane == "in":
                entry.update(family(t))
            else:
                entry["out_of_plane"] = family(t)
        return {
            "campaign": self.campaign,
            "tension_model": self.tension_model,
            "planes": list(self.planes),
            "tests": list(entries.values()),
            "reference_checks": [
                {"label": c.label, "setup": c.setup, "tests": list(c.tests), "reproduced": c.reproduced,
                 "rms_nominal_Hz": c.rms_nominal, "max_nominal_Hz": c.max_nominal, "EI_nominal": c.EI_nominal,
                 "EI_best": c.EI_best, "rms_best_Hz": c.rms_best, "statement": c.sentence()}
                for c in self.reference_checks
            ],
            "settings": self.settings.summary(),
        }


def _modes_of(modes: tuple[int, ...] | None, n_modes: int | None) -> tuple[int, ...]:
    """The modes shown of a family whose measured mode numbers are ``modes`` (None: none measured)."""
    if modes and n_modes is None:
        return tuple(modes)
    n = n_modes if n_modes is not None else 6
    if modes:
        n = max(n, max(modes))
    return tuple(range(1, n + 1))


#: ``plane`` of :func:`compare_forward` and ``forward --plane``: the families of modes computed.
PLANE_CHOICES = ("in", "out", "both")


def chosen_planes(plane: str | None, tests: list[Test]) -> tuple[str, ...]:
    """The planes computed for ``plane`` ("in", "out", "both"; None: "both" when one of ``tests`` has an
    out-of-plane frequency, else "in")."""
    if plane is None:
        plane = "both" if any("out" in (t.planes or ()) for t in tests) else "in"
    if plane not in PLANE_CHOICES:
        from ..core.errors import ModelError

        raise ModelError(f"must be one of {', '.join(PLANE_CHOICES)}, got {plane!r}", field="plane")
    return PLANES if plane == "both" else (plane,)


def compare_forward(campaign: Campaign, tests: list[str] | None = None, n_modes: int | None = None,
                    tension_model: str = "uniform", picked: dict | None = None,
                    plane: str | None = None) -> ForwardResult:
    """Compute every model for the selected tests of a campaign.

    Parameters
    ----------
    campaign : Campaign
    tests : list of test names, optional (default: all)
    n_modes : int, optional
        Modes to compute per plane; default the measured modes, at least 1..6.
    tension_model : {"uniform", "per-segment", "none"}
    picked : dict, optional
        {test name: (modes, frequencies)} or (modes, frequencies, planes)
        picked from records; they replace the table as ``measured`` (the
        table is then shown as a reference column, ``table``).
    plane : {"in", "out", "both"}, optional
        The families of modes: in-plane, out-of-plane or both. Default
        "both" when a selected test (or a pick) has an out-of-plane
        frequency, else "in".
    """
    settings = Settings(tension_model=tension_model)
    picked = picked or {}
    selected = campaign.tests if not tests else [campaign.test(n) for n in tests]
    measured_tests, tables = [], {}
    for test in selected:
        if test.name in picked:
            modes, freqs, *planes = picked[test.name]
            if test.frequencies is not None:
                tables[test.name] = test
            freqs = tuple(float(f) for f in freqs)
            test = replace(test, frequencies=freqs or None, modes=tuple(int(k) for k in modes) or None,
                           planes=(tuple(planes[0]) if planes and planes[0] is not None and freqs else None),
                           reference=())
        measured_tests.append(test)
    planes = chosen_planes(plane, measured_tests)
    families: dict[str, list[TestComparison]] = {p: [] for p in PLANES}
    for test in measured_tests:
        for p in planes:
            families[p].append(_compare_test(campaign, test, tables.get(test.name), p, n_modes, tension_model))
    checks = _reference_checks(campaign, [campaign.test(t.name) for t in measured_tests if t.name not in picked],
                               tension_model, planes)
    return ForwardResult(campaign.name, settings, families["in"], checks, out_of_plane=families["out"],
                         planes=planes)


def _compare_test(campaign: Campaign, test: Test, table: Test | None, plane: str, n_modes: int | None,
                  tension_model: str) -> TestComparison:
    """One test's comparison in one plane: its frequencies measured in that plane against that family."""
    cable = campaign.cable
    atts = campaign.setup(test.setup).attachments

    def in_plane(t: Test) -> list[int]:  # the indices of t's frequencies measured in this plane
        return [i for i, q in enumerate(t.planes or ()) if q == plane]

    mine = in_plane(test)
    measured_modes = tuple(test.modes[i] for i in mine)
    shown = _modes_of(measured_modes or None, n_modes)
    shown = tuple(sorted(set(shown) | set(measured_modes)))
    n = max(max(shown), 6 if n_modes is None else n_modes)
    idx = np.array(shown) - 1
    damping = None
    if has_dampers(atts):
        modes = complex_modes(cable, atts, test.tension, n, tension_model=tension_model, plane=plane)
        dsm_all, damping = modes.frequency, modes.damping[idx]
    else:
        dsm_all = batch_frequencies(cable, atts, test.tension, n, tension_model=tension_model, plane=plane)
    measured = None
    if mine:
        by_mode = {test.modes[i]: test.frequencies[i] for i in mine}
        measured = np.array([by_mode.get(k, np.nan) for k in shown])
    reference = {}
    for label, values in test.reference:
        ref_by_mode = {test.modes[i]: values[i] for i in mine}
        if ref_by_mode:
            reference[label] = np.array([ref_by_mode.get(k, np.nan) for k in shown])
    if table is not None:
        by_mode = {table.modes[i]: table.frequencies[i] for i in in_plane(table)}
        if by_mode:
            reference["table"] = np.array([by_mode.get(k, np.nan) for k in shown])
    return TestComparison(
        name=test.name, setup=test.setup, tension=test.tension, modes=shown, dsm=dsm_all[idx],
        taut_string=closed_form.taut_string(cable.length, cable.mass_per_length, test.tension, shown),
        beam_pinned=closed_form.beam_pinned(cable.length, cable.mass_per_length, test.tension, cable.EI, shown),
        measured=measured, reference=reference, damping=damping, plane=plane,
    )


def _printed_step(values) -> float:
    """The resolution a column was printed with (0.01 for 7.16, 0.0001 for 1.3587)."""
    decimals = 0
    for v in values:
        text = f"{v:.10f}".rstrip("0")
        decimals = max(decimals, len(text.split(".")[1]) if "." in text else 0)
    return 10.0 ** (-decimals)


def _reference_checks(campaign: Campaign, tests: list[Test], tension_model: str,
                      planes: tuple[str, ...] = ("in",)) -> list[ReferenceCheck]:
    """Group tests by (reference label, setup); compare and fit EI for each group.

    Columns named like a closed form ("taut_string", "beam_pinned") are
    compared with that formula; every other column with the DSM, each value
    with the mode of its own plane (only the values of ``planes`` count).
    """
    groups: dict[tuple[str, str], list[Test]] = {}
    for t in tests:
        for label, _ in t.reference:
            groups.setdefault((label, t.setup), []).append(t)
    cable = campaign.cable
    checks = []
    for (label, setup), members in groups.items():
        atts = campaign.setup(setup).attachments
        rows = []  # (tension, modes, values, plane)
        for t in members:
            values = np.array(dict(t.reference)[label])
            for p in planes:
                mine = np.array([q == p for q in t.planes], bool)
                if mine.any():
                    rows.append((t.tension, np.array(t.modes)[mine], values[mine], p))
        if not rows:
            continue
        step = _printed_step(np.concatenate([r[2] for r in rows]))

        def model(EI, rows=rows, atts=atts, label=label):
            out = []
            for H, modes, _, plane in rows:
                if "taut_string" in label:
                    out.append(closed_form.taut_string(cable.length, cable.mass_per_length, H, modes))
                elif "beam_pinned" in label:
                    out.append(closed_form.beam_pinned(cable.length, cable.mass_per_length, H, EI, modes))
                else:
                    f = batch_frequencies(cable, atts, H, int(modes.max()), EI=EI, tension_model=tension_model,
                                          plane=plane)
                    out.append(f[modes - 1])
            return np.concatenate(out)

        target = np.concatenate([r[2] for r in rows])
        modes_all = np.concatenate([r[1] for r in rows])
        diff = model(cable.EI) - target
        rms = float(np.sqrt(np.mean(diff**2)))
        worst = int(np.argmax(np.abs(diff)))
        if "taut_string" in label or cable.EI == 0:
            EI_best, rms_best = cable.EI, rms
        else:
            res = minimize_scalar(lambda lg, target=target: float(np.mean((model(math.exp(lg)) - target) ** 2)),
                                  bounds=(math.log(cable.EI) - 3, math.log(cable.EI) + 3), method="bounded",
                                  options={"xatol": 1e-6})
            EI_best, rms_best = math.exp(res.x), math.sqrt(res.fun)
        names = tuple(t.name for t in members if set(t.planes) & set(planes))
        checks.append(ReferenceCheck(label, setup, names, step, rms,
                                     float(abs(diff[worst])), int(modes_all[worst]), cable.EI, EI_best, rms_best))
    return checks
