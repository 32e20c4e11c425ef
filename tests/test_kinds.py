"""Parameter kinds: one record per kind (core/kinds), the same checks on every kind, the effects' names as
aliases without core importing the effects, the campaign's tolerance keys from core, and a toy kind added
from this file alone that parse_parameters and an identification take."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest

import stcs_ident
from stcs_ident import effects
from stcs_ident.core import kinds
from stcs_ident.core.errors import InputError
from stcs_ident.core.kinds import Kind, Tolerance
from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
from stcs_ident.core.parameters import Parameter, parse_parameters
from stcs_ident.diagnose.tables import parameter_rows
from stcs_ident.forward import batch_frequencies
from stcs_ident.identify import Measurement, identify
from stcs_ident.identify.corrected import corrected_campaign
from stcs_ident.report.identify_figures import parameter_label
from stcs_ident.report.identify_tables import parameters_table

PACKAGE = Path(stcs_ident.__file__).parent
BUILT_IN = ("tension", "EI", "length", "mass_per_length", "position", "mass", "stiffness", "coefficient",
            "end_stiffness")

CABLE = Cable(length=19.715, mass_per_length=16.6, EI=117338.3)
TENSION = 1.2e6
W1 = Attachment("W1", 7.0, mass=40.0, stiffness=1e3)
D1 = Damper("D1", 1.5, coefficient=2e4)
#: The solver is accurate to 1e-12 and the fits converge to 1e-14: exact data give the truth to 1e-6 relative
#: (the acceptance criterion of test_identify) with a wide margin.
EXACT_RTOL = 1e-6


# --------------------------------------------------------------------------
# One record per kind, the same checks on each
# --------------------------------------------------------------------------

def test_the_built_in_kinds_are_registered_in_order():
    assert kinds.names()[:len(BUILT_IN)] == BUILT_IN


@pytest.mark.parametrize("kind", kinds.kinds(), ids=lambda k: k.name)
def test_every_kind_declares_what_the_others_read(kind):
    assert kind.unit and kind.symbol and kind.attribute
    assert kind.bounds[0] < kind.bounds[1] and kind.grid[0] < kind.grid[1]
    assert kinds.get(kind.name) is kind
    for alias in kind.aliases:
        assert kinds.resolve(alias) == kind.name
    assert kinds.unit(kind.name) == kind.unit


@pytest.mark.parametrize("kind", [k for k in kinds.kinds() if k.override is not None], ids=lambda k: k.name)
def test_every_override_is_a_keyword_of_the_solver(kind):
    """The override a kind sets is one batch_frequencies takes: set to the nominal value, it changes nothing."""
    attachments = (D1, W1)  # in ascending position, the order of the per-attachment overrides
    if kind.belongs_to == "attachment":
        value = [getattr(a, kind.attribute, 0.0) for a in attachments]
    elif kind.belongs_to == "test":
        value = TENSION
    else:
        value = getattr(CABLE, kind.attribute)
    nominal = batch_frequencies(CABLE, attachments, TENSION, 3)
    overridden = batch_frequencies(CABLE, attachments, **{"tension": TENSION, "n_modes": 3, kind.override: value})
    # The same numbers through the same solver: equal to the last bits.
    np.testing.assert_allclose(overridden, nominal, rtol=1e-12, atol=0)


def test_one_unit_table_labels_a_zero_nominal_dashpot_in_newton_seconds_per_metre():
    """A coefficient whose nominal value is 0 has the value itself as variable: its unit is the dashpot's."""
    p = Parameter("coefficient", "D1", 0.0, 1.0, 0.0, 1e6, setup="S", index=0)
    assert not p.is_ratio and p.unit == "N s/m"
    assert parameter_label(p) == "coefficient (N s/m) (D1)"
    assert parameter_label(Parameter("mass", "W1", 0.0, 1.0, 0.0, 10.0)) == "mass (kg) (W1)"
    assert parameter_label(Parameter("stiffness", "W1", 0.0, 1.0, 0.0, 10.0)) == "stiffness (N/m) (W1)"


def test_the_diagnosis_report_units_come_from_the_kinds():
    values = {"damper": {"coefficient": 1e4, "position": 2.0}, "end_restraint": {"rotational_stiffness_A": 1e5,
                                                                                 "fixity_A": 0.5},
              "tension": {"ratio": {"T1": 1.01}}}
    rows = {r["parameter"]: r["unit"] for r in parameter_rows(values, {})}
    assert rows == {"coefficient": "N s/m", "position": "m", "rotational_stiffness_A": "N m/rad", "fixity_A": "-",
                    "ratio[T1]": "-"}


# --------------------------------------------------------------------------
# The effects' names and tolerances: one way, effects -> core
# --------------------------------------------------------------------------

def _imports(path: Path) -> list[str]:
    """Every module named by an import statement of ``path`` (relative ones with their dots)."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = "." * node.level + (node.module or "")
            out += [base] + [f"{base}.{a.name}" if node.module else base + a.name for a in node.names]
    return out


@pytest.mark.parametrize("floor", ["core", "io"])
def test_core_and_io_never_import_the_effects(floor):
    for path in sorted((PACKAGE / floor).rglob("*.py")):
        named = _imports(path)
        assert not [m for m in named if "effects" in m.split(".")], f"{path.relative_to(PACKAGE)} imports effects"


def test_the_effects_names_are_aliases_of_their_kinds():
    for e in effects.effects():
        if e.parameter_kind and e.name != e.parameter_kind:
            assert kinds.resolve(e.name) == e.parameter_kind


def test_every_tolerance_an_effect_declared_is_a_kind_s_and_accepted_by_a_campaign():
    """The keys and defaults the effect modules declared before the kinds held them (and the mass per length's,
    which no effect changes: identify carries it into σ)."""
    declared = {"tension": (0.02, True), "EI": (0.3, True), "position": (0.02, False), "mass": (0.02, True),
                "length": (0.002, True), "coefficient": (0.2, True), "mass_per_length": (0.01, True)}
    assert set(kinds.tolerance_keys()) == set(declared) == set(effects.tolerance_keys())
    for e in effects.effects():
        if e.tolerance is not None:
            assert (e.tolerance.default, e.tolerance.relative) == declared[e.tolerance.key]
            assert e.tolerance is kinds.get(e.parameter_kind).tolerance


def test_an_effect_with_a_tolerance_no_kind_has_is_refused():
    class Windy(effects.Effect):
        name = "windy"
        meaning = "a toy"
        parameter_kind = "EI"
        tolerance = Tolerance("wind", 0.1)

    with pytest.raises(ValueError, match="no parameter kind has"):
        effects.register(Windy())
    assert "windy" not in effects.names() and kinds.resolve("windy") is None


def test_a_kind_name_or_alias_cannot_be_taken_twice():
    with pytest.raises(ValueError, match="already taken"):
        kinds.register(Kind("EI", "N m^2", "EI", "cable", "EI"))
    with pytest.raises(ValueError, match="already taken"):
        kinds.register(Kind("flexural", "N m^2", "EI", "cable", "EI", aliases=("bending_stiffness",)))
    with pytest.raises(ValueError, match="already taken"):
        kinds.register(Kind("pull", "N", "H", "test", "tension", tolerance=Tolerance("tension", 0.1)))
    with pytest.raises(ValueError, match="belongs_to"):
        Kind("twist", "rad", "θ", "span", "twist")
    assert kinds.names()[:len(BUILT_IN)] == BUILT_IN and "flexural" not in kinds.names()


# --------------------------------------------------------------------------
# A toy kind, from this file alone
# --------------------------------------------------------------------------

@pytest.fixture
def linear_density():
    """The cable's mass per length under another name and symbol: one registration call."""
    kind = kinds.register(Kind("linear_density", "kg/m", "μ", "cable", "mass_per_length", attribute="mass_per_length"))
    yield kind
    kinds.unregister(kind.name)
    assert kinds.resolve("linear_density") is None


def _campaign(ratio: float, n_modes: int = 8) -> tuple[Campaign, dict]:
    """Exact frequencies of the bare cable with its mass per length ``ratio`` times the nominal one."""
    f = batch_frequencies(CABLE, (), TENSION, n_modes, mass_per_length=CABLE.mass_per_length * ratio)
    test = Test("T1", "bare", TENSION, tuple(f))
    campaign = Campaign("toy", CABLE, (Setup("bare"),), (test,))
    return campaign, {"T1": Measurement(test, np.arange(1, n_modes + 1), f, 0.005, "given")}


def test_a_toy_kind_is_parsed_like_a_built_in_one(linear_density):
    campaign, _ = _campaign(1.0)
    (p,) = parse_parameters(campaign, campaign.tests, "linear_density")
    assert (p.kind, p.member, p.nominal, p.lower, p.upper) == ("linear_density", None, 16.6, 0.5, 2.0)
    assert p.name == "linear_density_ratio" and p.unit == "kg/m"
    assert parameter_label(p) == "μ\u0303/μ"
    (q,) = parse_parameters(campaign, campaign.tests, "linear_density_ratio", bounds={"linear_density": (0.9, 1.2)})
    assert (q.lower, q.upper) == (0.9, 1.2)
    with pytest.raises(InputError, match="takes no"):
        parse_parameters(campaign, campaign.tests, "linear_density[W1]")


@pytest.mark.parametrize("method", ["lsq", "contour"])
def test_a_toy_kind_is_identified_from_exact_frequencies(linear_density, method):
    campaign, picked = _campaign(1.04)
    params = "linear_density" if method == "lsq" else "EI,linear_density"
    result = identify(campaign, ["T1"], params, method=method, picked=picked)
    truth = [1.04] if method == "lsq" else [1.0, 1.04]
    np.testing.assert_allclose(result.estimate, truth, rtol=EXACT_RTOL, atol=0)
    table = parameters_table(result).set_index("parameter")
    assert table.loc["linear_density_ratio", "unit"] == "kg/m"
    # The corrected campaign carries the value on the field the kind names.
    corrected = corrected_campaign(campaign, result)
    assert math.isclose(corrected.cable.mass_per_length, 1.04 * 16.6, rel_tol=EXACT_RTOL)
