"""Slips on the record path are refused with the right hint, never numbered into a confident answer.

Before (issue 34): a stay campaign with its tension typed in kN and a record had its peaks numbered 10, 18, 21
at MAC 0.48, 0.04, 0.00, none doubtful, and identify gave 4.31 ± 0.82 kN; a record read at twice its sampling
rate gave 3.439 ± 0.037 MN and EI 0.24x; an HDF5 record at 10x its rate said "option '--test': no selected
test" with no --test given. The peaks' own harmonic series (spectra/harmonic.py) is now compared with the
nominal family first (spectra/scale_check.py).
"""

from __future__ import annotations

import re
import shutil
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

from stcs_ident.cli.main import main
from stcs_ident.core.errors import InputError, NumberingWarning
from stcs_ident.core.model import Cable, Campaign, Setup, Test
from stcs_ident.forward import natural_frequencies
from stcs_ident.io.campaign import load_campaign
from stcs_ident.simulate.simulate import Ambient, Impulse
from stcs_ident.simulate.simulate_campaign import simulate_campaign
from stcs_ident.spectra.pipeline import analyse_test
from stcs_ident.spectra.scale_check import check_scale

ROOT = Path(__file__).resolve().parent.parent
HANGER = ROOT / "campaigns" / "hanger-hidden-mass"
#: A 120 m stay at 3.4 MN (the made-up stay of campaigns/damped-stay without its damper).
STAY = Cable(length=120.0, mass_per_length=80.0, EI=2.0e5, EA=1.5e9, inclination=np.radians(30.0))
TENSION = 3.4e6


@pytest.fixture(scope="module")
def stay(tmp_path_factory) -> Path:
    """A simulated stay campaign: one 120-s record at 50 Hz, a blow and wind."""
    nominal = Campaign("stay", STAY, (Setup("bare"),), (Test("T1", "bare", TENSION),))
    return simulate_campaign(nominal, tmp_path_factory.mktemp("slips") / "stay", positions=[27.6, 60.0, 85.2],
                             duration=120.0, sampling_rate=50.0, impulses=[Impulse(1.0, 20.4, 50.0)],
                             ambient=Ambient(5.0), snr_db=30.0, seed=3)


def _variant(source: Path, tmp_path: Path, edit=None, rate: float | None = None, record_format: str = "") -> Path:
    """A copy of the campaign ``source`` with its TOML text edited, its records' sampling rate attribute set, and
    a ``[record_format]`` table added."""
    out = tmp_path / source.name
    shutil.copytree(source, out)
    toml = out / "campaign.toml"
    text = toml.read_text(encoding="utf-8")
    if edit is not None:
        text = edit(text)
    toml.write_text(text + ("\n[record_format]\n" + record_format + "\n" if record_format else ""), encoding="utf-8")
    if rate is not None:
        for record in (out / "records").glob("*.h5"):
            with h5py.File(record, "r+") as h5:
                h5.attrs["sampling_rate"] = rate
    return out


def _refusal(capsys, *argv) -> str:
    assert main(list(argv)) == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("stcs-ident:")
             and "warning" not in line]
    assert len(lines) == 1, lines
    return lines[0]


def _scale(text: str, factor: float) -> str:
    return re.sub(r"tension = ([0-9.e+]+)", lambda m: f"tension = {float(m.group(1)) * factor!r}", text)


def _mass(text: str, factor: float) -> str:
    return re.sub(r"mass_per_length = ([0-9.e+]+)", lambda m: f"mass_per_length = {float(m.group(1)) * factor!r}",
                  text)


def test_a_tension_typed_in_kN_on_a_record_is_refused_naming_the_tension(stay, tmp_path, capsys):
    campaign = _variant(stay, tmp_path, lambda t: _scale(t, 1e-3))
    line = _refusal(capsys, "identify", str(campaign))
    assert "field 'test[T1].tension'" in line and "tension in kN?" in line, line
    assert "--test" not in line and "--no-plausibility-check" in line


@pytest.mark.slow
def test_spectra_warns_and_marks_every_number_doubtful(stay, tmp_path):
    campaign = load_campaign(_variant(stay, tmp_path, lambda t: _scale(t, 1e-3)))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        spectra = analyse_test(campaign, campaign.tests[0])
    assert any(issubclass(w.category, NumberingWarning) and "harmonic series" in str(w.message) for w in caught)
    assert spectra.implausible_scale and all(spectra.doubtful)
    (check,) = spectra.scale
    assert check.mode == 1 and check.ratio > 10  # f ∝ √T on a string: √1000 = 31.6, bending holds it at ~15
    assert spectra.summary()["scale_check"][0]["implausible"] is True


def test_the_correct_campaign_passes_the_scale_check(stay):
    campaign = load_campaign(stay)
    spectra = analyse_test(campaign, campaign.tests[0])
    # three sensors: the numbered modes' shapes confirm their numbers (MAC 0.95-1.00), so no series is looked for
    assert spectra.scale == () and not any(spectra.doubtful) and np.median(spectra.mac) > 0.95
    # and the peaks' own series is on the nominal scale all the same
    freqs = [p.frequency for p in spectra.peaks.peaks]
    check = check_scale("in", freqs, [p.uncertainty for p in spectra.peaks.peaks],
                        lambda n: natural_frequencies(campaign.cable, (), TENSION, n))
    assert check.conclusive and not check.implausible
    assert check.ratio == pytest.approx(1.0, abs=0.02)  # the stated tension is the truth; sag moves mode 1 by 0.1 %


@pytest.mark.slow
@pytest.mark.parametrize(("edit", "rate", "field", "hint"), [
    (lambda t: _mass(t, 1e3), None, "tension", "g/m"),                    # kg/m typed as g/m
    (lambda t: _mass(t, 1e-3), None, "mass_per_length", "t/m"),           # t/m typed for kg/m
    (lambda t: _mass(t, 9.80665), None, "", "N/m"),                       # its weight per length, N/m
    (lambda t: _scale(t, 1e-6), None, "test[T1].tension", "tension in MN?"),
    (None, 100.0, "'sampling_rate'", "sampling rate 2× too high?"),
    (None, 25.0, "'sampling_rate'", "sampling rate 2× too low?"),
    (None, 500.0, "'sampling_rate'", "sampling rate 10× too high?"),
], ids=["mass-g/m", "mass-t/m", "mass-N/m", "tension-MN", "rate-x2", "rate-x0.5", "rate-x10"])
def test_every_slip_on_the_stays_record_is_refused_with_its_hint(stay, tmp_path, capsys, edit, rate, field, hint):
    campaign = _variant(stay, tmp_path, edit, rate)
    for command in ("identify", "diagnose"):
        line = _refusal(capsys, command, str(campaign))
        assert field in line and hint in line, line
        assert "--test" not in line


@pytest.mark.slow
def test_a_campaign_rate_that_overrides_the_file_is_named_in_the_refusal(stay, tmp_path, capsys):
    campaign = _variant(stay, tmp_path, record_format="sampling_rate = 100.0\noverride_sampling_rate = true")
    line = _refusal(capsys, "identify", str(campaign))
    assert "field 'test[T1].record_format.sampling_rate'" in line and "(100 Hz) 2× too high?" in line, line


@pytest.mark.slow
def test_the_hangers_tension_in_kN_is_refused_and_its_correct_campaign_is_not(tmp_path, capsys):
    """The issue's case: the shipped hanger with tension = 1000 for 500 kN (its record's peak at 9.133 Hz was
    paired with nominal mode 2, 1.3x apart, and the check guessed 'tension in mN')."""
    campaign = _variant(HANGER, tmp_path, lambda t: _scale(t, 1e-3))
    line = _refusal(capsys, "identify", str(campaign))
    assert "tension in kN?" in line and "mN" not in line, line
    assert main(["identify", str(HANGER), "--json", str(tmp_path / "ok.json")]) == 0


@pytest.mark.slow
def test_the_override_fits_anyway(stay, tmp_path, capsys):
    campaign = _variant(stay, tmp_path, None, 100.0)
    code = main(["identify", str(campaign), "--no-plausibility-check"])
    err = capsys.readouterr().err
    assert code == 2 and "every picked mode's number is doubtful" in err  # the numbers stay doubtful: no answer
    assert "option '--test'" not in err


@pytest.mark.slow
def test_a_library_call_refuses_in_one_line(stay, tmp_path):
    from stcs_ident import identify

    campaign = load_campaign(_variant(stay, tmp_path, None, 100.0))
    with warnings.catch_warnings(), pytest.raises(InputError) as err:
        warnings.simplefilter("ignore", NumberingWarning)
        identify(campaign)
    assert err.value.field == "sampling_rate" and "\n" not in str(err.value)
