"""The effect registry: one module per effect, no other list of effect names, the same checks on every
effect, and a toy effect added from this file alone that the diagnosis can name.
"""

from __future__ import annotations

import ast
import functools
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import stcs_ident
from stcs_ident import effects
from stcs_ident.cli.main import build_parser
from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
from stcs_ident.core.planes import PLANES
from stcs_ident.diagnose import diagnose
from stcs_ident.effects.base import Effect, Option, Quantity, Truth, positive_ratio
from stcs_ident.effects.unmodeled_support import OnePlaneSupport
from stcs_ident.forward import batch_frequencies
from stcs_ident.identify.problem import Measurement
from stcs_ident.simulate.effects import Effects, true_model

PACKAGE = Path(stcs_ident.__file__).parent
DOCS = Path(__file__).resolve().parents[1] / "docs" / "effects.md"
BUILT_IN = effects.names()

CABLE = Cable(length=8.0, mass_per_length=30.0, EI=2.0e5)
W1 = Attachment("W1", 2.7, mass=15.0)
#: A damper near end A, optimal for mode 1 (η = c π x_d/(l √(H m)) = 1 at 4e5 N), for the damper effects.
D1 = Damper("D1", 0.2, coefficient=math.sqrt(4e5 * 30.0) / (math.pi * 0.2 / 8.0))


def _points(name: str) -> list:
    """The recorded attachments of the samples: W1, and D1 for the damper effects."""
    return [W1, D1] if name.startswith("damper") else [W1]


# --------------------------------------------------------------------------
# One home per effect
# --------------------------------------------------------------------------

def _strings(tree: ast.AST):
    """String constants of a module that are not docstrings."""
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            yield node


@functools.cache
def _parsed() -> tuple:
    return tuple((path, ast.parse(path.read_text(encoding="utf-8"))) for path in sorted(PACKAGE.rglob("*.py")))


def _modules():
    yield from _parsed()  # each module parsed once per session (the package's every file, for several checks)


def test_each_effect_name_is_defined_in_exactly_one_module_of_the_effects_package():
    defining: dict = {}  # the value of each `name = "<constant>"` assignment -> the modules that make it
    for path, tree in _modules():
        for node in ast.walk(tree):
            if (isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "name" for t in node.targets)
                    and isinstance(node.value, ast.Constant)):
                defining.setdefault(node.value.value, []).append(path.relative_to(PACKAGE).as_posix())
    for name in BUILT_IN:
        assert defining.get(name, []) == [f"effects/{name}.py"], (name, defining.get(name, []))


def test_no_other_list_of_effect_names_remains_in_the_package():
    """Outside stcs_ident/effects/ no code string names an effect. ``tension``, ``length`` and ``damper`` are
    left out of the check: they are also the names of identification parameters, solver overrides and the
    campaign's ``[[setup.damper]]`` table."""
    only_effects = set(BUILT_IN) - {"tension", "length", "damper"}
    for path, tree in _modules():
        rel = path.relative_to(PACKAGE).as_posix()
        if rel.startswith("effects/"):
            continue
        for node in _strings(tree):
            assert node.value not in only_effects, f"{rel}:{node.lineno} names the effect {node.value!r}"


def test_every_effect_is_documented_for_users():
    text = DOCS.read_text(encoding="utf-8")
    for name in BUILT_IN:
        assert f"## `{name}`" in text, f"docs/effects.md has no section for {name}"


def test_cli_help_and_simulate_options_come_from_the_registry():
    parser = build_parser()
    sub = parser._subparsers._group_actions[0].choices
    help_text = " ".join(sub["diagnose"].format_help().split())
    for name in BUILT_IN:
        assert name in help_text
    flags = {a for action in sub["simulate"]._actions for a in action.option_strings}
    for e in effects.effects():
        if e.option is not None:
            assert e.option.flag in flags


# --------------------------------------------------------------------------
# The same checks on every registered effect
# --------------------------------------------------------------------------

#: A value of each built-in effect's simulator keyword, and a bad one.
SAMPLES = {
    "tension": (1.03, 0.0),
    "bending_stiffness": (1.2, -1.0),
    "attachment_position": ({"W1": 3.1}, {"W1": -1.0}),
    "attachment_mass": ({"W1": 17.0}, {"W1": -2.0}),
    "unmodeled_mass": ((2.0, 5.0), (-2.0, 5.0)),
    "unmodeled_support": ((1e4, 5.0), (1e4, math.nan)),
    "support_in_plane": ((1e4, 5.0), (-1e4, 5.0)),
    "support_out_of_plane": ((1e4, 5.0), (1e4, math.inf)),
    "end_restraint": ((1e5, math.inf), (1.0,)),
    "length": (1.01, 0.0),
    "damper": ((1e4, 5.0), (-1.0, 5.0)),
    "damper_coefficient": ({"D1": 2e3}, {"D1": -1.0}),
}


def test_every_built_in_effect_has_a_sample():
    assert set(SAMPLES) == set(BUILT_IN)


@pytest.mark.parametrize("effect", effects.effects(), ids=lambda e: e.name)
def test_every_effect_declares_what_the_others_read(effect):
    assert effect.name and effect.meaning and effect.quantities
    assert all(q.per in (None, "test", "attachment") for q in effect.quantities)
    assert effect.truth_key and effects.by_truth_key(effect.truth_key) is effect
    if effect.tolerance is not None:
        assert effect.tolerance.default > 0
    assert effect.unmodeled or effect.parameter_kind


@pytest.mark.parametrize("name", BUILT_IN)
def test_every_effect_changes_the_true_model_and_round_trips_to_json(name):
    effect = effects.get(name)
    good, bad = SAMPLES[name]
    hidden = Effects(**{effect.truth_key: good})
    assert hidden.names == [name]
    nominal = true_model(CABLE, _points(name), 4e5, None)
    true = true_model(CABLE, _points(name), 4e5, hidden)
    assert true != nominal
    # both planes: an effect may act in one plane only (support_out_of_plane)
    f0 = np.concatenate([batch_frequencies(*nominal, 4, plane=p) for p in PLANES])
    f1 = np.concatenate([batch_frequencies(*true, 4, plane=p) for p in PLANES])
    assert not np.allclose(f0, f1, rtol=1e-9)
    assert json.loads(json.dumps(hidden.to_dict())) == json.loads(json.dumps({effect.truth_key: effect.truth_json(
        effect.check_truth(good, "x"))}))
    with pytest.raises(ValueError) as err:
        Effects(**{effect.truth_key: bad})
    assert err.value.field.startswith(f"effects.{effect.truth_key}")


@pytest.mark.parametrize("name", BUILT_IN)
def test_every_effect_frees_parameters_and_reports_them_in_its_own_units(name):
    points = _points(name)
    campaign = Campaign("c", CABLE, (Setup("S", tuple(points)),), (Test("T1", "S", 4e5), Test("T2", "S", 5e5)))
    # an effect of one plane is considered with both planes' modes only
    planes = PLANES if isinstance(effects.get(name), OnePlaneSupport) else ("in",)
    d = diagnose(campaign, effects=name, max_effects=1, workers=1,
                 picked={t.name: Measurement(t, np.tile(np.arange(1, 7), len(planes)),
                                             np.concatenate([batch_frequencies(CABLE, points, t.tension, 6, plane=p)
                                                             for p in planes]),
                                             1e-4, "given", planes=[p for p in planes for _ in range(6)])
                         for t in campaign.tests})
    fit = d.fits[(name,)]
    values, sigmas = d.parameters(fit)
    assert set(values[name]) >= {q.key for q in effects.get(name).quantities}
    assert effects.get(name).describe(values[name], sigmas[name], CABLE)


# --------------------------------------------------------------------------
# A toy effect, from this file alone
# --------------------------------------------------------------------------

class MassPerLength(Effect):
    """The cable's mass per length differs from the nominal one (a toy: sheathing, grease, ice)."""

    name = "mass_per_length"
    meaning = "the cable's mass per length differs from nominal"
    quantities = (Quantity("mass_per_length", "kg/m"),)
    parameter_kind = "mass_per_length"
    truth_key = "mass_per_length_ratio"
    option = Option("--mass-per-length-ratio", "R", "true / nominal mass per length")

    def describe(self, values, sigmas, cable):
        return f"a mass per length of {values['mass_per_length']:.4g} kg/m"

    def check_truth(self, value, field):
        return positive_ratio(value, field)

    def apply_truth(self, truth: Truth, value):
        truth.cable = replace(truth.cable, mass_per_length=truth.cable.mass_per_length * value)


@pytest.fixture
def toy():
    effect = effects.register(MassPerLength())
    yield effect
    effects.unregister(effect.name)


def test_a_toy_effect_added_from_a_test_file_is_named_by_the_diagnosis(toy):
    setup = Setup("S", (W1,))
    rng = np.random.default_rng(5)
    hidden = Effects(mass_per_length_ratio=1.08)
    tests, picked = [], {}
    for i, tension in enumerate((4.0e5, 5.0e5)):
        f = batch_frequencies(*true_model(CABLE, setup.attachments, tension, hidden), 6)
        sigma = 5e-5 * f
        test = Test(f"T{i + 1}", "S", tension)
        tests.append(test)
        picked[test.name] = Measurement(test, np.arange(1, 7), f + rng.normal(0.0, sigma), sigma, "given")
    campaign = Campaign("toy", CABLE, (setup,), tuple(tests))
    d = diagnose(campaign, picked=picked, effects="tension,bending_stiffness,length,mass_per_length")
    cause = d.summary()["cause"]
    assert cause["effects"] == ["mass_per_length"] and cause["principal"] == "mass_per_length"
    # 5e-5 frequency noise on 12 modes: the mass per length to a few 1e-5 (3 % of the change as the limit)
    assert cause["parameters"]["mass_per_length"]["mass_per_length"] == pytest.approx(1.08 * 30.0, rel=0.003)
    assert "mass per length" in cause["description"]
    sub = build_parser()._subparsers._group_actions[0].choices
    assert "--mass-per-length-ratio" in sub["simulate"].format_help()
    assert "mass_per_length" in " ".join(sub["diagnose"].format_help().split())


def test_registering_a_taken_name_is_refused():
    with pytest.raises(ValueError, match="already registered"):
        effects.register(effects.get("tension"))
