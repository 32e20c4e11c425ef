"""Facts checked on the full-scale test data (docs/model.md, 'Known differences from the source paper')."""

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from stcs_ident.core.model import Attachment
from stcs_ident.forward import natural_frequencies
from stcs_ident.forward import reference as ref
from stcs_ident.forward.assembly import CableBatch, Topology
from stcs_ident.forward.compare import compare_forward
from stcs_ident.forward.roots import solve_modes
from stcs_ident.io.campaign import load_campaign

ROOT = Path(__file__).resolve().parents[1]
CAMPAIGN = ROOT / "campaigns" / "han2020"
DATA = CAMPAIGN / "data"


@pytest.fixture(scope="module")
def campaign():
    return load_campaign(CAMPAIGN)


@pytest.fixture(scope="module")
def computed():
    return pd.read_csv(DATA / "paper_computed.csv")


def _column(computed, level, method):
    rows = computed[(computed.case == "case1") & (computed.level == level) & (computed.method == method)]
    return rows.sort_values("mode").frequency_Hz.to_numpy()


@pytest.mark.parametrize("level", [4, 5])
def test_paper_case1_columns_need_EI_93_9(campaign, computed, level):
    """With EI = 93.9 kN m² the paper's own columns are reproduced: its DSM
    within 0.015 Hz, TS and BT within 0.01 Hz (the columns are printed to
    0.01 Hz, and 93.9 is itself a rounded fit)."""
    test = campaign.test(f"case1-L{level}")
    cable = replace(campaign.cable, EI=93.9e3)
    modes = np.arange(1, 7)
    dsm = natural_frequencies(cable, [], test.tension, 6)
    np.testing.assert_allclose(dsm, _column(computed, level, "paper_dsm"), atol=0.015, rtol=0)
    ts = ref.taut_string(cable.length, cable.mass_per_length, test.tension, modes)
    np.testing.assert_allclose(ts, _column(computed, level, "taut_string"), atol=0.01, rtol=0)
    bt = ref.beam_pinned(cable.length, cable.mass_per_length, test.tension, cable.EI, modes)
    np.testing.assert_allclose(bt, _column(computed, level, "beam_pinned"), atol=0.01, rtol=0)
    # and with Table 1's E·I mode 6 is about 0.5 Hz higher than the paper's DSM
    nominal = natural_frequencies(campaign.cable, [], test.tension, 6)
    assert 0.4 < nominal[5] - _column(computed, level, "paper_dsm")[5] < 0.6


def test_forward_states_the_EI_discrepancy(campaign):
    result = compare_forward(campaign, ["case1-L4", "case1-L5"])
    check = next(c for c in result.reference_checks if c.label == "paper_dsm" and c.setup == "case1")
    assert not check.reproduced
    assert check.EI_best == pytest.approx(93.9e3, rel=0.01)
    assert "does NOT reproduce 'paper_dsm'" in check.sentence()
    assert "93.9 kN m²" in check.sentence() or "94.0 kN m²" in check.sentence()


def _table12_cable(campaign):
    return campaign.cable  # Table 1 values, EI = E·I, EA = E·A


def _table12_tension(cable, e):
    return cable.weight_per_length * cable.length / (8 * e)


def _quarter_masses(cable):
    return [Attachment(f"M{i}", cable.length * i / 4, 8.3) for i in (1, 2, 3)]


@pytest.mark.parametrize("e", [0.0128, 0.0114, 0.0107])
def test_table12_is_reproduced_without_sag_extensibility(campaign, e):
    """Table 12 (the paper's FEM and its own method) agrees within 0.3 % with
    the model that ignores sag-extensibility: it does not validate sag."""
    table = pd.read_csv(DATA / "table12.csv")
    rows = table[np.isclose(table.sag_ratio, e)].sort_values("mode")
    cable = _table12_cable(campaign)
    f = natural_frequencies(cable, _quarter_masses(cable), _table12_tension(cable, e), 6, tension_model="none")
    np.testing.assert_allclose(f, rows.fem_Hz, rtol=3e-3)
    np.testing.assert_allclose(f, rows.paper_Hz, rtol=3e-3)


def test_table12_with_uniform_additional_tension(campaign):
    """With sag-extensibility the first symmetric mode leaves 1.36 Hz and
    rises past the first antisymmetric one (λ² ≈ 138 ≫ 4π²). The design notes'
    check table (3.016, 3.429, 5.332 Hz) is reproduced to 1e-3 when the
    attachments' weights are left out of the static profile and of Eq. (2);
    with their weights, as Eq. (2) states, the symmetric mode is at 3.67 Hz
    (checked against the independent finite-element model in test_fe_agreement)."""
    cable = _table12_cable(campaign)
    H = _table12_tension(cable, 0.0128)
    atts = _quarter_masses(cable)
    none = natural_frequencies(cable, atts, H, 3, tension_model="none")
    uniform = natural_frequencies(cable, atts, H, 3)
    assert none[0] == pytest.approx(1.362, abs=1e-3)
    assert uniform[0] == pytest.approx(none[1], rel=1e-9)  # antisymmetric: untouched by sag
    assert 3.3 < uniform[1] < 3.8  # first symmetric mode

    weightless = _batch_without_attachment_weights(cable, atts, H)
    f = solve_modes(weightless, np.zeros(3, dtype=int), np.arange(1, 4)) / (2 * math.pi)
    np.testing.assert_allclose(f, [3.016, 3.429, 5.332], rtol=1e-3)  # the check table prints 4 digits
    per_seg = _batch_without_attachment_weights(cable, atts, H, "per-segment")
    f = solve_modes(per_seg, np.zeros(3, dtype=int), np.arange(1, 4)) / (2 * math.pi)
    np.testing.assert_allclose(f, [3.431, 5.844, 8.942], rtol=1e-3)  # FE model of the doc: ~1e-3


def _batch_without_attachment_weights(cable, atts, H, model="uniform"):
    one = lambda v: np.array([v], float)
    return CableBatch(
        Topology(3, True, True, False, model), length=one(cable.length), mass_per_length=one(cable.mass_per_length),
        EI=one(cable.EI), tension=one(H), EA=one(cable.EA), weight=one(cable.weight_per_length), gcos=one(0.0),
        positions=np.array([[a.position for a in atts]]), masses=np.array([[a.mass for a in atts]]),
        springs=np.zeros((1, 3)), end_a=one(np.inf), end_b=one(np.inf),
    )
