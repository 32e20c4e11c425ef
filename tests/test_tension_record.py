"""One record to one tension (tension --record, identify/quick_record.py) and a record's peaks alone (spectra FILE).

The truth is the simulator's (the exact model's modes superposed, benchmarks/tension_record.py draws the members);
the stated σ carries the frequencies' 1σ from the record and the tolerances of the length (0.2 %), the mass per
length (1 %) and a given EI (30 %), which the true member is drawn within.
"""

from __future__ import annotations

import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from stcs_ident import tension_from_record
from stcs_ident.cli.main import main
from stcs_ident.core.errors import InputError
from stcs_ident.core.model import Cable
from stcs_ident.io.records.hdf5 import write_record
from stcs_ident.simulate.simulate import Ambient, Impulse, simulate_record_with_truth

ROOT = Path(__file__).resolve().parent.parent
STAY = Cable(length=120.0, mass_per_length=80.0, EI=2.0e5, EA=1.5e9, inclination=math.radians(30.0))
TENSION = 3.4e6


@pytest.fixture(scope="module")
def stay_record(tmp_path_factory) -> Path:
    """A 5-minute record of the stay at 50 Hz: a blow and wind, three sensors."""
    record, _ = simulate_record_with_truth(STAY, (), TENSION, [27.6, 60.0, 85.2], duration=300.0, sampling_rate=50.0,
                                           impulses=[Impulse(1.0, 20.4, 50.0)], ambient=Ambient(5.0), snr_db=30.0,
                                           seed=11)
    path = tmp_path_factory.mktemp("record") / "stay.h5"
    write_record(record, path)
    return path


def _run(*argv) -> int:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return main([str(a) for a in argv])


def test_a_stays_record_gives_its_tension_within_its_sigma(stay_record):
    result = tension_from_record(stay_record, 120.0, 80.0, EA=1.5e9, inclination=30.0)
    tension, sigma = result.tension.tension("exact")
    assert abs(tension - TENSION) <= 3 * sigma, (tension, sigma)  # 3σ: the stated σ's claim, one draw
    assert sigma < 0.03 * TENSION  # and an answer worth having: the length's and mass's tolerances dominate it
    numbered = sorted(p["mode"] for p in result.peaks if p["mode"] is not None)
    assert numbered[:10] == list(range(1, 11))  # numbered from the spacing alone
    assert result.series.fundamental == pytest.approx(math.sqrt(TENSION / 80.0) / 240.0, rel=0.01)
    summary = result.summary()
    assert {"record", "peaks", "series", "methods", "inputs"} <= set(summary)
    assert summary["record"]["channels"] == ["A1", "A2", "A3"] and summary["record"]["sampling_rate"] == 50.0
    assert "from the record" in summary["inputs"]["uncertainty_source"]


@pytest.mark.slow
def test_the_command_line_answers_and_writes_the_json(stay_record, tmp_path, capsys):
    out = tmp_path / "t.json"
    assert _run("tension", "--record", stay_record, "--length", "120", "--mass", "80", "--EA", "1.5e9",
                "--inclination", "30", "--json", out) == 0
    text = capsys.readouterr().out
    assert "peaks numbered from their own spacing" in text and "exact" in text
    data = json.loads(out.read_text())
    assert data["record"]["path"] == str(stay_record) and data["peaks"][0]["mode"] == 1
    assert abs(data["methods"]["exact"]["tension"] / TENSION - 1) < 0.03


@pytest.mark.slow
def test_a_text_record_with_a_preamble_and_decimal_commas_reads_with_its_options(stay_record, tmp_path, capsys):
    import h5py

    with h5py.File(stay_record) as h5:
        acc, fs = h5["acceleration"][:9000], float(h5.attrs["sampling_rate"])
    lines = ["Export of run 7", "Operator;X", "", "time;acc1;acc2;acc3;battery"]
    lines += [";".join([f"{k / fs:.2f}".replace(".", ",")] + [f"{v:.6e}".replace(".", ",") for v in row] + ["12,5"])
              for k, row in enumerate(acc)]
    path = tmp_path / "run7.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert _run("tension", "--record", path, "--length", "120", "--mass", "80", "--EA", "1.5e9", "--inclination",
                "30", "--separator", ";", "--decimal", ",", "--channels", "acc1,acc2,acc3") == 0
    out = capsys.readouterr().out
    assert "header line found at line 3" in out and "battery" in out  # the preamble and the column left out, said
    # a rate that contradicts the time column: refused naming both and the option to type
    assert _run("tension", "--record", path, "--length", "120", "--mass", "80", "--separator", ";", "--decimal", ",",
                "--channels", "acc1,acc2,acc3", "--sampling-rate", "100") == 2
    err = capsys.readouterr().err
    assert "100 Hz" in err and "50 Hz" in err and "--override-sampling-rate" in err
    assert "override_sampling_rate" not in err  # the command line's option, not the campaign key
    # spectra on the file lists its peaks unnumbered and points to tension --record
    assert _run("spectra", path, "--separator", ";", "--decimal", ",", "--channels", "acc1,acc2,acc3") == 0
    out = capsys.readouterr().out
    assert "unnumbered" in out and "tension --record" in out


def test_refusals_name_the_option(stay_record, capsys):
    assert _run("tension", "--length", "120", "--mass", "80", "--frequencies", "0.87", "--header-row", "3") == 2
    assert "option '--header-row': is a reader option: it goes with --record" in capsys.readouterr().err
    assert _run("tension", "--record", stay_record, "--length", "120", "--mass", "80", "--modes", "1,2") == 2
    assert "option '--modes': goes with --frequencies" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:  # argparse's own refusal of the pair
        _run("tension", "--record", stay_record, "--frequencies", "1", "--length", "120", "--mass", "80")
    assert exit_.value.code == 2 and "not allowed with argument --record" in capsys.readouterr().err
    assert _run("spectra", ROOT / "campaigns" / "hanger-hidden-mass", "--unit", "g") == 2
    assert "option '--unit': is a reader option" in capsys.readouterr().err
    # a reader's fix is said as the option to type (a text file without a time column)
    assert _run("tension", "--record", ROOT / "campaigns" / "han2020" / "data" / "tensions.csv", "--length", "20",
                "--mass", "16") == 2
    err = capsys.readouterr().err
    assert "--time-column" in err and "--sampling-rate" in err and "time_column" not in err, err


def test_peaks_that_several_spacings_explain_are_refused(tmp_path):
    """A single mode (a short stiff hanger sampled slowly: mode 2 beyond the band) numbers itself no way."""
    hanger = Cable(length=6.0, mass_per_length=40.0, EI=2e5, inclination=math.radians(90))
    record, truth = simulate_record_with_truth(hanger, (), 6e5, [1.4, 3.0, 4.3], duration=120.0, sampling_rate=60.0,
                                              impulses=[Impulse(1.0, 2.0, 5.0)], snr_db=30.0, seed=2)
    assert truth.frequencies[0] < 27.0 and (truth.frequencies.size == 1 or truth.frequencies[1] > 27.0)  # one mode
    # below 0.45 x 60 Hz
    path = tmp_path / "h.h5"
    write_record(record, path)
    with pytest.raises(InputError) as err:
        tension_from_record(path, 6.0, 40.0, EI=2e5, inclination=90.0)
    assert "do not number themselves" in err.value.message and "--frequencies" in err.value.message


@pytest.mark.slow
def test_the_stated_sigma_covers_the_truth_on_stays_and_hangers(tmp_path):
    """12 members (6 stays, 6 hangers, 10-minute records; benchmarks/tension_record.py's draws, seeds not used to
    tune anything): the truth within 3σ, or inside the range where the modes do not see EI, in at least 11 (at
    the claimed 99.7 % two misses in 12 have a chance of 0.07 %; benchmarks/README.md has the figures over 80
    draws per kind)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import tension_record

    z = []
    for k, kind in enumerate(["stay", "hanger"] * 6):
        _, value = tension_record.run_case(kind, 600.0, 31000 + k, tmp_path)
        z.append(np.inf if value is None else value)
    assert sum(v <= 3 for v in z) >= 11, z
