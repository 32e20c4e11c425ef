"""Tests of campaign.toml reading and writing (stcs_ident.io.campaign)."""

from __future__ import annotations

import csv
import dataclasses
import math
import runpy
from pathlib import Path

import pytest

from stcs_ident.core.errors import CampaignError, InputError
from stcs_ident.core.model import Attachment, Boundary, Cable, Campaign, Setup, Test
from stcs_ident.io.campaign import campaign_to_toml, load_campaign

HAN2020 = Path(__file__).resolve().parents[1] / "campaigns" / "han2020"

# A small valid campaign; each bad input below is one textual edit of it.
BASE = """\
[campaign]
name = "base"

[cable]
length = 20.0
mass_per_length = 16.6
EI = 1.0e5
boundary = "clamped"

[[setup]]
name = "bare"

[[setup]]
name = "loaded"

  [[setup.attachment]]
  name = "W1"
  position = 10.0
  mass = 8.3

[[test]]
name = "T1"
setup = "bare"
tension = 1.0e6
frequencies = [7.0, 14.0]

[[test]]
name = "T2"
setup = "loaded"
tension = 1.1e6
"""

SECOND_ATTACHMENT = """
  [[setup.attachment]]
  name = "{name}"
  position = {position}
  mass = 1.0
"""


def edited(old: str, new: str) -> str:
    """BASE with ``old`` replaced by ``new``; ``old`` must occur exactly once."""
    assert BASE.count(old) == 1, old
    return BASE.replace(old, new)


def after_w1(text: str) -> str:
    """BASE with ``text`` added after attachment W1 (inside setup "loaded")."""
    return edited("  mass = 8.3\n", "  mass = 8.3\n" + text)


def write_campaign(directory: Path, text: str | bytes) -> Path:
    """Write ``text`` as ``directory/campaign.toml`` and return the file."""
    directory.mkdir(parents=True, exist_ok=True)
    file = directory / "campaign.toml"
    if isinstance(text, bytes):
        file.write_bytes(text)
    else:
        file.write_text(text, encoding="utf-8")
    return file


def assert_one_line_naming(err: InputError, file: Path, field: str | None) -> None:
    """The error is a CampaignError naming ``file`` and ``field``, on one line."""
    text = str(err)
    assert isinstance(err, CampaignError)
    assert "\n" not in text
    assert err.file == str(file)
    assert err.field == field
    if field is None:
        assert text.startswith(f"{file}: ")
    else:
        assert text.startswith(f"{file}: field '{field}': ")


def read_csv(name: str) -> list[dict[str, str]]:
    with open(HAN2020 / "data" / name, newline="") as stream:
        return list(csv.DictReader(stream))


# --------------------------------------------------------------------------
# han2020
# --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def han2020() -> Campaign:
    return load_campaign(HAN2020)


def test_han2020_cable(han2020):
    cable = han2020.cable
    assert han2020.name == "han2020"
    assert han2020.directory == str(HAN2020)
    # Values are written with these decimal digits, so they read back exactly.
    assert cable.length == 19.715
    assert cable.mass_per_length == 16.6
    assert cable.EI == 117338.3
    assert cable.EA == 4.1382e8
    assert cable.inclination == 0.0
    assert cable.gravity == 9.81
    assert cable.boundary_a.is_clamped and cable.boundary_b.is_clamped


def test_han2020_cable_matches_table1(han2020):
    # E I and E A of Table 1; rel 1e-12 allows the float noise of the product.
    assert han2020.cable.EI == pytest.approx(1.9e11 * 6.1757e-7, rel=1e-12)
    assert han2020.cable.EA == pytest.approx(1.9e11 * 2.178e-3, rel=1e-12)


def test_han2020_setups(han2020):
    assert [s.name for s in han2020.setups] == ["case1", "case2", "case3"]
    assert han2020.setup("case1").attachments == ()
    for case, mass in (("case2", 8.3), ("case3", 16.6)):
        (weight,) = han2020.setup(case).attachments
        assert (weight.name, weight.position, weight.mass, weight.stiffness) == ("W1", 9.8575, mass, 0.0)


def test_han2020_tests_match_tensions_csv(han2020):
    rows = read_csv("tensions.csv")
    assert len(han2020.tests) == len(rows) == 15
    for row in rows:
        test = han2020.test(f"{row['case']}-L{row['level']}")
        assert test.setup == row["case"]
        assert test.tension == float(row["tension_N"])  # exact: same decimal text
        assert (test.frequencies is not None) == (int(row["level"]) >= 4)


def test_han2020_measured_frequencies_match_csv(han2020):
    rows = [r for r in read_csv("measured.csv") if (r["case"], r["level"]) == ("case1", "4")]
    test = han2020.test("case1-L4")
    assert test.modes == tuple(int(r["mode"]) for r in rows) == (1, 2, 3, 4, 5, 6)
    # Exact: both sides parse the same decimal text (44.40 and 44.4 are one float).
    assert test.frequencies == tuple(float(r["frequency_Hz"]) for r in rows)
    assert test.frequencies[0] == 7.24


def test_han2020_data_are_shipped():
    names = {"tensions.csv", "measured.csv", "paper_computed.csv", "table12.csv", "README.md"}
    assert names <= {p.name for p in (HAN2020 / "data").iterdir()}


def test_han2020_toml_is_up_to_date(capsys):
    script = runpy.run_path(str(HAN2020 / "make_campaign.py"))  # leaves no __pycache__ beside it
    assert script["main"](["--check"]) == 0, capsys.readouterr().out


def test_toml_file_path_is_accepted(han2020):
    assert load_campaign(HAN2020 / "campaign.toml") == han2020
    assert load_campaign(str(HAN2020)) == han2020


# --------------------------------------------------------------------------
# Valid variants
# --------------------------------------------------------------------------


def load_text(tmp_path: Path, text: str) -> Campaign:
    return load_campaign(write_campaign(tmp_path / "c", text))


def test_defaults(tmp_path):
    campaign = load_text(tmp_path, edited('boundary = "clamped"\n', ""))
    cable = campaign.cable
    assert (cable.EA, cable.inclination, cable.gravity) == (None, 0.0, 9.81)
    assert cable.boundary_a.is_clamped and cable.boundary_b.is_clamped
    assert campaign.test("T1").modes == (1, 2)
    assert campaign.test("T2").frequencies is None and campaign.test("T2").record is None
    (weight,) = campaign.setup("loaded").attachments
    assert weight.stiffness == 0.0
    assert campaign.description == ""


def test_integers_are_accepted_for_floats(tmp_path):
    campaign = load_text(
        tmp_path, edited("length = 20.0", "length = 20").replace("tension = 1.0e6", "tension = 1000000")
    )
    assert campaign.cable.length == 20.0
    assert campaign.test("T1").tension == 1e6


def test_inclination_is_stored_in_radians(tmp_path):
    campaign = load_text(tmp_path, edited("EI = 1.0e5", "EI = 1.0e5\ninclination = -30"))
    assert campaign.cable.inclination == math.radians(-30)


@pytest.mark.parametrize(
    "value, a, b",
    [
        ('"pinned"', 0.0, 0.0),
        ("2.5e6", 2.5e6, 2.5e6),
        ("0", 0.0, 0.0),
        ('["clamped", 2.0e6]', math.inf, 2.0e6),
        ('["pinned", "clamped"]', 0.0, math.inf),
    ],
)
def test_boundary_forms(tmp_path, value, a, b):
    cable = load_text(tmp_path, edited('boundary = "clamped"', f"boundary = {value}")).cable
    assert (cable.boundary_a.rotational_stiffness, cable.boundary_b.rotational_stiffness) == (a, b)


# --------------------------------------------------------------------------
# Round trip
# --------------------------------------------------------------------------


def reload(tmp_path: Path, campaign: Campaign) -> Campaign:
    """Write ``campaign`` with campaign_to_toml and read it back."""
    return load_campaign(write_campaign(tmp_path / "round", campaign_to_toml(campaign, header="a\nb")))


def test_round_trip_han2020(tmp_path, han2020):
    back = reload(tmp_path, han2020)
    assert back == dataclasses.replace(han2020, directory=back.directory)


def test_round_trip_every_field(tmp_path):
    cable = Cable(
        length=42.3,
        mass_per_length=7.05,
        EI=0.0,
        EA=None,
        inclination=math.radians(23.7),
        gravity=9.80665,
        boundary_a=Boundary.pinned(),
        boundary_b=Boundary(3.3e5),
    )
    setups = (
        Setup("none"),
        Setup(
            "two",
            (Attachment("damper", 1.5, mass=12.0, stiffness=4.5e4), Attachment('sensor "7"', 21.15, 0.2)),
        ),
    )
    tests = (
        Test("a", "two", 2.5e6, frequencies=(3.1, 6.2, 12.5), modes=(1, 2, 4), record="records/a.h5"),
        Test("b", "none", 123.0),
    )
    description = 'quotes " backslash \\ tab \t newline \n unicode θ ctrl \x01'
    campaign = Campaign("every-field", cable, setups, tests, description)
    back = reload(tmp_path, campaign)
    assert back == dataclasses.replace(campaign, directory=back.directory)


@pytest.mark.parametrize("degrees", [0.0, 1.0, -30.0, 45.5, 89.9, 12.3456789])
def test_round_trip_inclination_is_exact(tmp_path, degrees):
    cable = Cable(10.0, 1.0, 1.0, inclination=math.radians(degrees))
    campaign = Campaign("tilt", cable)
    assert reload(tmp_path, campaign).cable.inclination == cable.inclination
    assert f"inclination = {degrees!r}\n" in campaign_to_toml(campaign)


def test_header_is_comments():
    text = campaign_to_toml(Campaign("x", Cable(1.0, 1.0, 0.0)), header="line one\n\nline three")
    assert text.startswith("# line one\n#\n# line three\n\n[campaign]\n")


# --------------------------------------------------------------------------
# Bad inputs: one case each, the error names the file and the field
# --------------------------------------------------------------------------

W1 = "setup[loaded].attachment[W1]"
CABLE_TABLE = '[cable]\nlength = 20.0\nmass_per_length = 16.6\nEI = 1.0e5\nboundary = "clamped"\n'

BAD = {
    # missing / mistyped
    "missing cable.length": (edited("length = 20.0\n", ""), "cable.length"),
    "missing campaign.name": (edited('name = "base"\n', ""), "campaign.name"),
    "missing test tension": (edited("tension = 1.1e6\n", ""), "test[T2].tension"),
    "missing test setup": (edited('setup = "loaded"\n', ""), "test[T2].setup"),
    "missing attachment position": (edited("  position = 10.0\n", ""), f"{W1}.position"),
    "missing setup name": (edited('name = "bare"\n', ""), "setup[#1].name"),
    "missing cable table": (edited(CABLE_TABLE, ""), "cable"),
    "string length": (edited("length = 20.0", 'length = "abc"'), "cable.length"),
    "boolean EI": (edited("EI = 1.0e5", "EI = true"), "cable.EI"),
    "string frequencies": (edited("[7.0, 14.0]", '["7.0", 14.0]'), "test[T1].frequencies"),
    "float modes": (edited("[7.0, 14.0]", "[7.0, 14.0]\nmodes = [1.0, 2.0]"), "test[T1].modes"),
    "modes length": (edited("[7.0, 14.0]", "[7.0, 14.0]\nmodes = [1, 2, 3]"), "test[T1].modes"),
    "numeric setup name": (edited('name = "bare"', "name = 3"), "setup[#1].name"),
    "cable not a table": ("cable = 1\n" + edited(CABLE_TABLE, ""), "cable"),
    # unknown keys
    "unknown key in cable": (edited("EI = 1.0e5", 'EI = 1.0e5\ncolour = "red"'), "cable.colour"),
    "unknown key in test": (edited('name = "T1"', 'name = "T1"\ntemperature = 20.0'), "test[T1].temperature"),
    "unknown key in attachment": (after_w1('  colour = "red"\n'), f"{W1}.colour"),
    "unknown key in setup": (edited('name = "bare"', 'name = "bare"\nnote = "x"'), "setup[bare].note"),
    "unknown key in campaign": (edited('name = "base"', 'name = "base"\nauthor = "me"'), "campaign.author"),
    "unknown top-level table": (BASE + "\n[extra]\nx = 1\n", "extra"),
    # out of range
    "negative length": (edited("length = 20.0", "length = -20.0"), "cable.length"),
    "zero length": (edited("length = 20.0", "length = 0"), "cable.length"),
    "negative mass_per_length": (
        edited("mass_per_length = 16.6", "mass_per_length = -16.6"),
        "cable.mass_per_length",
    ),
    "zero mass_per_length": (
        edited("mass_per_length = 16.6", "mass_per_length = 0.0"),
        "cable.mass_per_length",
    ),
    "negative EI": (edited("EI = 1.0e5", "EI = -1.0"), "cable.EI"),
    "zero EA": (edited("EI = 1.0e5", "EI = 1.0e5\nEA = 0.0"), "cable.EA"),
    "negative tension": (edited("tension = 1.0e6", "tension = -1.0e6"), "test[T1].tension"),
    "zero tension": (edited("tension = 1.1e6", "tension = 0.0"), "test[T2].tension"),
    "nan tension": (edited("tension = 1.1e6", "tension = nan"), "test[T2].tension"),
    "negative attachment mass": (edited("mass = 8.3", "mass = -8.3"), f"{W1}.mass"),
    "negative attachment stiffness": (after_w1("  stiffness = -1.0\n"), f"{W1}.stiffness"),
    "position beyond length": (edited("position = 10.0", "position = 25.0"), f"{W1}.position"),
    "position at end B": (edited("position = 10.0", "position = 20.0"), f"{W1}.position"),
    "position zero": (edited("position = 10.0", "position = 0.0"), f"{W1}.position"),
    "inclination 95": (edited("EI = 1.0e5", "EI = 1.0e5\ninclination = 95"), "cable.inclination"),
    "inclination -90.5": (edited("EI = 1.0e5", "EI = 1.0e5\ninclination = -90.5"), "cable.inclination"),
    "negative gravity": (edited("EI = 1.0e5", "EI = 1.0e5\ngravity = -9.81"), "cable.gravity"),
    # inconsistent
    "two attachments at one position": (
        after_w1(SECOND_ATTACHMENT.format(name="W2", position=10.0)),
        "setup[loaded].attachment[W2].position",
    ),
    "duplicate attachment names": (
        after_w1(SECOND_ATTACHMENT.format(name="W1", position=12.0)),
        f"{W1}.name",
    ),
    "unknown setup in a test": (edited('setup = "bare"', 'setup = "nope"'), "test[T1].setup"),
    "duplicate setup names": (edited('name = "loaded"', 'name = "bare"'), "setup[bare].name"),
    "duplicate test names": (edited('name = "T2"', 'name = "T1"'), "test[T1].name"),
    # boundary
    "boundary free": (edited('"clamped"', '"free"'), "cable.boundary"),
    "boundary of three": (edited('"clamped"', "[1, 2, 3]"), "cable.boundary"),
    "boundary negative": (edited('"clamped"', "-5"), "cable.boundary"),
    "boundary boolean": (edited('"clamped"', "true"), "cable.boundary"),
    "boundary bad end B": (edited('"clamped"', '["clamped", "free"]'), "cable.boundary"),
    # reserved
    "damping present": (after_w1("  damping = 0.0\n"), f"{W1}.damping"),
}


@pytest.mark.parametrize("text, field", BAD.values(), ids=BAD.keys())
def test_bad_input_names_file_and_field(tmp_path, text, field):
    file = write_campaign(tmp_path / "bad", text)
    with pytest.raises(CampaignError) as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, field)


def test_attachment_damping_points_to_the_damper_table(tmp_path):
    file = write_campaign(tmp_path / "bad", after_w1("  damping = 0.0\n"))
    with pytest.raises(CampaignError, match=r"give a damper as a \[\[setup.damper\]\]"):
        load_campaign(file.parent)


def test_unknown_key_is_quoted_in_message(tmp_path):
    file = write_campaign(tmp_path / "bad", edited("EI = 1.0e5", 'EI = 1.0e5\ncolour = "red"'))
    with pytest.raises(CampaignError, match="unknown key 'colour'"):
        load_campaign(file)


def test_directory_without_campaign_toml(tmp_path):
    with pytest.raises(CampaignError) as info:
        load_campaign(tmp_path)
    assert_one_line_naming(info.value, tmp_path / "campaign.toml", None)


def test_missing_file(tmp_path):
    file = tmp_path / "nowhere.toml"
    with pytest.raises(CampaignError) as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, None)


@pytest.mark.parametrize(
    "garbage",
    ["this is not TOML at all\n{{{ ]]]\n", "[cable\nlength = 1\n", b"\xff\xfe\x00garbage\x81"],
    ids=["text", "unclosed table", "binary"],
)
def test_garbage_file(tmp_path, garbage):
    file = write_campaign(tmp_path / "bad", garbage)
    with pytest.raises(CampaignError, match="not a (valid )?TOML file") as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, None)


def test_input_file_is_not_written(tmp_path):
    file = write_campaign(tmp_path / "c", BASE)
    before = (file.read_bytes(), file.stat().st_mtime_ns)
    load_campaign(file)
    assert (file.read_bytes(), file.stat().st_mtime_ns) == before


# --------------------------------------------------------------------------
# [tolerance]
# --------------------------------------------------------------------------

TOLERANCE_CAMPAIGN = """
[campaign]
name = "t"

[cable]
length = 10.0
mass_per_length = 5.0
EI = 100.0

[tolerance]
{body}
"""


def test_tolerances_default_to_the_effects_and_a_campaign_overrides_them(tmp_path):
    from stcs_ident import effects

    campaign = load_campaign(write_campaign(tmp_path, TOLERANCE_CAMPAIGN.format(body="tension = 0.005\nposition = 0.1")))
    assert dict(campaign.tolerance) == {"position": 0.1, "tension": 0.005}
    assert effects.tolerance(campaign, "tension") == 0.005
    assert effects.tolerance(campaign, "attachment_position") == 0.1
    assert effects.tolerance(campaign, "bending_stiffness") == effects.get("bending_stiffness").tolerance.default == 0.3
    assert effects.tolerance(campaign, "unmodeled_mass") is None
    assert reload(tmp_path, campaign).tolerance == campaign.tolerance


@pytest.mark.parametrize("body,field", [
    ("tension = -0.01", "tolerance.tension"),
    ("EI = nan", "tolerance.EI"),
    ("EI = \"a lot\"", "tolerance.EI"),
    ("coefficient_of_wind = 0.1", "tolerance.coefficient_of_wind"),
])
def test_bad_tolerances_are_refused_naming_the_key(tmp_path, body, field):
    file = write_campaign(tmp_path, TOLERANCE_CAMPAIGN.format(body=body))
    with pytest.raises(CampaignError) as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, field)


# --------------------------------------------------------------------------
# A test's stated frequency uncertainty
# --------------------------------------------------------------------------

def test_a_stated_uncertainty_is_one_number_or_one_per_frequency_and_round_trips(tmp_path):
    one = load_text(tmp_path / "one", edited("frequencies = [7.0, 14.0]\n",
                                             "frequencies = [7.0, 14.0]\nuncertainty = 0.005\n"))
    assert one.test("T1").uncertainty == (0.005, 0.005) and one.test("T2").uncertainty is None
    each = load_text(tmp_path / "each", edited("frequencies = [7.0, 14.0]\n",
                                               "frequencies = [7.0, 14.0]\nuncertainty = [0.002, 0.004]\n"))
    assert each.test("T1").uncertainty == (0.002, 0.004)
    assert reload(tmp_path, each).test("T1").uncertainty == (0.002, 0.004)


@pytest.mark.parametrize("value,why", [("[0.002]", "has 1 values but frequencies has 2"),
                                       ("0.0", "must be > 0 Hz"), ("-1e-3", "must be > 0 Hz"),
                                       ("20.0", "below its frequency"), ('"0.01"', "must be a number")])
def test_a_bad_stated_uncertainty_names_its_field(tmp_path, value, why):
    file = write_campaign(tmp_path / "c", edited("frequencies = [7.0, 14.0]\n",
                                                 f"frequencies = [7.0, 14.0]\nuncertainty = {value}\n"))
    with pytest.raises(InputError) as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, "test[T1].uncertainty")
    assert why in str(info.value)


def test_an_uncertainty_without_frequencies_is_refused(tmp_path):
    file = write_campaign(tmp_path / "c", edited("tension = 1.1e6\n", "tension = 1.1e6\nuncertainty = 0.01\n"))
    with pytest.raises(InputError) as info:
        load_campaign(file)
    assert_one_line_naming(info.value, file, "test[T2].uncertainty")
    assert "needs the test's frequencies" in str(info.value)


def test_identification_weighs_the_frequencies_by_their_stated_uncertainty(tmp_path):
    from stcs_ident.identify import identify

    plain = load_text(tmp_path / "plain", BASE)
    stated = load_text(tmp_path / "stated", edited("frequencies = [7.0, 14.0]\n",
                                                   "frequencies = [7.0, 14.0]\nuncertainty = [0.002, 0.004]\n"))
    rounded, given = identify(plain, ["T1"], "tension"), identify(stated, ["T1"], "tension")
    assert given.summary()["tests"][0]["uncertainty_source"] == "stated uncertainty"
    assert given.summary()["tests"][0]["uncertainty"] == [0.002, 0.004]
    assert "table rounding" in rounded.summary()["tests"][0]["uncertainty_source"]  # 1 Hz / sqrt 12 from "7.0"
