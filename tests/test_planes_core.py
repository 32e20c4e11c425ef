"""The two planes in the model objects: channel directions, per-plane attachment values, tests' planes, and
their campaign files (stcs_ident.core.planes, core.model, io.campaign)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from stcs_ident.core.errors import CampaignError, ModelError
from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
from stcs_ident.core.planes import (
    check_direction,
    direction_angle,
    direction_plane,
    plane_overrides,
    plane_view,
)
from stcs_ident.core.record import Record
from stcs_ident.io.campaign import campaign_to_toml, load_campaign
from stcs_ident.io.test_record import record_reading

STAY = Cable(length=300.0, mass_per_length=100.0, EI=1.0e5, EA=2.0e9, inclination=math.radians(30))


@pytest.mark.parametrize("given, expected", [
    ("in", "in"), ("OUT", "out"), (" axial ", "axial"), (0, "in"), (90.0, "out"), (450, "out"), ("12.5", 12.5),
    (-30, -30.0), (270, -90.0), (180, 180.0),
])
def test_a_direction_is_a_name_or_an_angle_in_degrees(given, expected):
    assert check_direction(given) == expected


@pytest.mark.parametrize("bad", ["up", "", None, True, math.nan, math.inf, [1, 2]])
def test_a_wrong_direction_is_refused_naming_its_field(bad):
    with pytest.raises(ModelError, match="direction"):
        check_direction(bad, "channels.acc1.direction")


def test_the_plane_a_channel_sees():
    assert direction_plane("in") == "in" and direction_plane("out") == "out" and direction_plane("axial") is None
    assert direction_plane(30.0) == "in" and direction_plane(60.0) == "out" and direction_plane(-120.0) == "out"
    assert direction_angle("out") == pytest.approx(math.pi / 2) and direction_angle("axial") is None


def test_out_of_plane_drops_the_sag_term_and_takes_the_out_of_plane_values():
    atts = (Attachment("clamp", 20.0, mass=30.0, stiffness=1e4, stiffness_out=3e4),
            Attachment("weight", 50.0, mass=10.0, stiffness=2e3),
            Damper("d", 6.0, 5.0, 1e3, coefficient=2e5, angle=math.radians(30)))
    cable_in, in_plane = plane_view(STAY, atts, "in")
    cable_out, out_plane = plane_view(STAY, atts, "out")
    assert cable_in == STAY and cable_out == dataclasses.replace(STAY, EA=None)
    by_name_in = {a.name: a for a in in_plane}
    by_name_out = {a.name: a for a in out_plane}
    assert [a.name for a in in_plane] == [a.name for a in out_plane]  # count and order kept for overrides
    assert by_name_in["clamp"].stiffness == 1e4 and by_name_out["clamp"].stiffness == 3e4
    assert by_name_out["weight"].stiffness == 2e3  # no stiffness_out: the same spring in both planes
    assert by_name_out["clamp"].mass == by_name_in["clamp"].mass == 30.0  # a clamped mass moves in both
    # The damper along its axis at 30°: cos² = 3/4 in-plane, sin² = 1/4 out-of-plane, of every value.
    assert by_name_in["d"].coefficient == pytest.approx(1.5e5) and by_name_out["d"].coefficient == pytest.approx(5e4)
    assert by_name_in["d"].mass == pytest.approx(3.75) and by_name_out["d"].stiffness == pytest.approx(250.0)


def test_a_damper_in_the_plane_of_the_cable_is_a_point_out_of_it():
    d = Damper("d", 6.0, 5.0, 1e3, coefficient=2e5)
    (_, [inside]), (_, [outside]) = plane_view(STAY, [d], "in"), plane_view(STAY, [d], "out")
    assert inside is d
    assert type(outside) is Attachment and (outside.mass, outside.stiffness) == (0.0, 0.0)


def test_overrides_follow_the_plane():
    atts = (Attachment("clamp", 20.0, stiffness=1e4, stiffness_out=3e4), Attachment("spring", 40.0, stiffness_out=5.0),
            Damper("d", 60.0, coefficient=2e5, angle=math.radians(60)))
    given = {"stiffnesses": np.array([[2e4, 0.0, 0.0], [1e4, 0.0, 8.0]]), "coefficients": np.array([0.0, 0.0, 4e5])}
    out = plane_overrides(atts, given, "out")
    np.testing.assert_allclose(out["stiffnesses"], [[6e4, 5.0, 0.0], [3e4, 5.0, 6.0]])  # 8 sin²60° = 6
    np.testing.assert_allclose(out["coefficients"], [0.0, 0.0, 3e5])
    inside = plane_overrides(atts, given, "in")
    np.testing.assert_allclose(inside["coefficients"], [0.0, 0.0, 1e5])  # 4e5 cos²60°
    np.testing.assert_allclose(inside["stiffnesses"], [[2e4, 0.0, 0.0], [1e4, 0.0, 2.0]])


def test_a_damper_refuses_a_stiffness_out_and_a_wild_angle():
    with pytest.raises(ModelError, match="angle, not a stiffness_out"):
        Damper("d", 6.0, coefficient=1e5, stiffness_out=1.0)
    with pytest.raises(ModelError, match="±180"):
        Damper("d", 6.0, coefficient=1e5, angle=4.0)


def test_mode_numbers_count_per_plane():
    test = Test("T", "S", 4e6, (0.37, 0.33, 0.67), modes=(1, 1, 2), planes=("in", "out", "out"))
    assert test.planes == ("in", "out", "out")
    assert Test("T", "S", 4e6, (0.37, 0.67)).planes == ("in", "in")
    with pytest.raises(ModelError, match="distinct within each plane"):
        Test("T", "S", 4e6, (0.33, 0.34), modes=(1, 1), planes=("out", "out"))
    with pytest.raises(ModelError, match="planes"):
        Test("T", "S", 4e6, (0.33, 0.34), planes=("out",))
    with pytest.raises(ModelError, match="in-plane"):
        Test("T", "S", 4e6, (0.33,), planes=("sideways",))


def test_a_record_carries_one_direction_per_channel():
    acc = np.zeros((10, 3))
    acc[0] = 1.0
    record = Record(acc, 100.0, ("a", "b", "c"), (1.0, 1.0, 1.0), channel_directions=("in", "90", 12))
    assert record.directions == ("in", "out", 12.0)
    assert Record(acc, 100.0, ("a", "b", "c"), (1.0, 1.0, 1.0)).directions == ("in",) * 3
    with pytest.raises(ModelError, match="one per channel"):
        Record(acc, 100.0, ("a", "b", "c"), (1.0, 1.0, 1.0), channel_directions=("in", "out"))
    with pytest.raises(ModelError, match="channel 'b'"):
        Record(acc, 100.0, ("a", "b", "c"), (1.0, 1.0, 1.0), channel_directions=("in", "up", "in"))


CAMPAIGN = """\
[campaign]
name = "planes"

[cable]
length = 300.0
mass_per_length = 100.0
EI = 1.0e5
EA = 2.0e9
inclination = 30.0

[channels]
acc1 = {{ position = 20.0, direction = "in" }}
acc2 = {{ position = 20.0, direction = "out" }}
acc3 = {{ position = 20.0, direction = "axial" }}
acc4 = 45.0

[[setup]]
name = "S"
  [[setup.attachment]]
  name = "clamp"
  position = 40.0
  mass = 20.0
  stiffness = 1.0e4
  stiffness_out = 2.0e4
  [[setup.damper]]
  name = "d"
  position = 6.0
  coefficient = 2.0e5
  angle = 30.0

[[test]]
name = "T1"
setup = "S"
tension = 4.0e6
frequencies = [0.37, 0.333, 0.667]
modes = [1, 1, 2]
{planes}
"""


def _write(tmp_path, text):
    path = tmp_path / "campaign.toml"
    path.write_text(text)
    return path


def test_a_campaign_gives_planes_directions_angles_and_round_trips(tmp_path):
    campaign = load_campaign(_write(tmp_path, CAMPAIGN.format(planes='planes = ["in", "out", "out"]')))
    assert campaign.tests[0].planes == ("in", "out", "out")
    assert dict(campaign.channel_directions) == {"acc1": "in", "acc2": "out", "acc3": "axial"}
    assert record_reading(campaign, campaign.tests[0]).directions == {"acc1": "in", "acc2": "out", "acc3": "axial"}
    clamp, damper = sorted(campaign.setup("S").attachments, key=lambda a: a.name)
    assert clamp.stiffness_out == 2.0e4 and damper.angle == pytest.approx(math.radians(30))
    again = tmp_path / "again"
    again.mkdir()
    back = load_campaign(_write(again, campaign_to_toml(campaign)))
    assert back == dataclasses.replace(campaign, directory=back.directory)


def test_a_campaign_gives_the_structure_s_frequencies_and_round_trips(tmp_path):
    text = CAMPAIGN.format(planes="").replace("modes = [1, 1, 2]", "") + "\n[structure]\nfrequencies = [0.52, 1.3]\n"
    campaign = load_campaign(_write(tmp_path, text))
    assert campaign.structural_frequencies == (0.52, 1.3)
    again = tmp_path / "again"
    again.mkdir()
    assert load_campaign(_write(again, campaign_to_toml(campaign))).structural_frequencies == (0.52, 1.3)
    for bad, field in (("frequencies = [-1.0]", "structure.frequencies"), ("modes = [1]", "structure.modes")):
        other = tmp_path / bad.split()[0]
        other.mkdir()
        with pytest.raises((CampaignError, ModelError)) as err:
            load_campaign(_write(other, text.replace("frequencies = [0.52, 1.3]", bad)))
        assert err.value.field == field


def test_a_campaign_without_planes_is_in_plane(tmp_path):
    campaign = load_campaign(_write(tmp_path, CAMPAIGN.format(planes="").replace("modes = [1, 1, 2]", "")))
    assert campaign.tests[0].planes == ("in", "in", "in")
    assert "planes =" not in campaign_to_toml(campaign)  # written only where a plane is out


@pytest.mark.parametrize("planes, field, message", [
    ('planes = ["in", "sideways", "out"]', "test[T1].planes", "out-of-plane"),
    ('planes = ["in", "out"]', "test[T1].planes", "has 2 entries"),
    ('planes = ["in", "in", "out"]', "test[T1].modes", "distinct"),
])
def test_wrong_planes_name_the_field(tmp_path, planes, field, message):
    with pytest.raises((CampaignError, ModelError)) as err:
        load_campaign(_write(tmp_path, CAMPAIGN.format(planes=planes)))
    assert err.value.field == field and message in str(err.value)


def test_a_wrong_channel_direction_names_the_channel(tmp_path):
    text = CAMPAIGN.format(planes="").replace("modes = [1, 1, 2]", "").replace('direction = "axial"', 'direction = "up"')
    with pytest.raises(CampaignError) as err:
        load_campaign(_write(tmp_path, text))
    assert err.value.field == "channels.acc3.direction" and "angle in degrees" in str(err.value)


def test_a_campaign_round_trip_of_the_model_objects():
    campaign = Campaign("c", STAY, (Setup("S", (Attachment("a", 10.0, stiffness_out=1.0),)),),
                        (Test("T", "S", 4e6, (0.33,), planes=("out",), channel_directions={"x": 45.0}),))
    assert campaign.tests[0].channel_directions == (("x", 45.0),)
    assert record_reading(campaign, campaign.tests[0]).directions == {"x": 45.0}
