"""Run settings: one frozen object, validated when built (the error names the field), recorded in every result."""

from pathlib import Path

import pytest

from stcs_ident.core.errors import InputError
from stcs_ident.core.settings import Settings
from stcs_ident.forward.compare import compare_forward
from stcs_ident.identify import identify
from stcs_ident.io.campaign import load_campaign

HAN = Path(__file__).resolve().parents[1] / "campaigns" / "han2020"


@pytest.mark.parametrize(("field", "value"), [("tension_model", "sagging"), ("scale_rule", "always"),
                                              ("max_effects", 3), ("max_effects", True),
                                              ("all_hypotheses", "yes")])
def test_a_setting_out_of_range_names_its_field(field, value):
    with pytest.raises(InputError) as caught:
        Settings(**{field: value})
    assert caught.value.field == field and repr(value) in caught.value.message


def test_settings_are_frozen_and_plain_data():
    s = Settings(tension_model="none", max_effects=1)
    with pytest.raises(AttributeError):
        s.tension_model = "uniform"
    assert s.summary() == {"tension_model": "none", "scale_rule": "auto", "max_effects": 1, "all_hypotheses": False}


def test_results_record_their_settings():
    campaign = load_campaign(HAN)
    forward = compare_forward(campaign, ["case1-L4"], tension_model="none")
    assert forward.settings == Settings(tension_model="none") and forward.tension_model == "none"
    assert forward.summary()["tension_model"] == "none" and forward.summary()["settings"]["tension_model"] == "none"
    result = identify(campaign, ["case1-L4"], "tension,EI", tension_model="none", scale_rule="never")
    assert result.settings == Settings(tension_model="none", scale_rule="never")
    assert result.covariance_scale == 1.0  # the rule recorded is the rule applied
    assert result.summary()["settings"]["scale_rule"] == "never"
    with pytest.raises(InputError) as caught:
        identify(campaign, ["case1-L4"], "tension,EI", tension_model="sagging")
    assert caught.value.field == "tension_model"
