"""Each bad input of the reliability findings, built by hand: exit 2 and one line naming the file and the field.

tests/test_fuzz.py checks that no input ends in a traceback, a hang or a
modified input; these check what the one line says for each finding.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from stcs_ident.cli.main import main
from tests.fuzz_inputs import write_base_campaign


@pytest.fixture
def campaign(tmp_path):
    """The fuzzer's base campaign (a hanger with a clamp; T1 a table, T2 a record)."""
    return write_base_campaign(tmp_path / "c")


def refusal(argv, capsys) -> str:
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exit_:  # argparse's refusals
        code = exit_.code
    err = [line for line in capsys.readouterr().err.splitlines() if not line.startswith(("spectra: ", "simulate: "))]
    assert code == 2 and len(err) == 1, (code, err)
    return err[0]


def edit(campaign, old, new):
    toml = campaign / "campaign.toml"
    text = toml.read_text(encoding="utf-8")
    assert old in text
    toml.write_text(text.replace(old, new, 1), encoding="utf-8")
    return str(toml)


@pytest.mark.parametrize("old, new, field", [
    ("tension = 0.02", "tension = 1" + "0" * 400, "field 'tolerance.tension'"),
    ('  mass = 15.0\n', "  mass = 15.0\n" + "".join(f'  [[setup.attachment]]\n  name = "M{k}"\n  position = '
                                                   f"{0.1 + 0.1 * k:.1f}\n" for k in range(51)),
     "field 'setup[S].attachment'"),
    ("frequencies = [", f"modes = [1, 2, 3, 4, {2**62}]\nfrequencies = [", "field 'test[T1].modes'"),
    ("frequencies = [", "frequencies = [1e300, ", "field 'test[T1].frequencies'"),
    ("frequencies = [", "reference = {paper = [1e300, 1, 1, 1, 1]}\nfrequencies = [",
     "field 'test[T1].reference.paper'"),
])
def test_a_campaign_value_out_of_range_names_the_file_and_the_field(campaign, capsys, old, new, field):
    toml = edit(campaign, old, new)
    line = refusal(["forward", campaign], capsys)
    assert toml in line and field in line


@pytest.mark.parametrize("old, new, field", [
    ("tension = 4.0e5", "tension = 1e-320", "field 'test[T1].tension'"),
    ("EI = 2.0e5", "EI = 1e-300", "field 'cable.EI'"),
    ("length = 8.0", "length = 1e308", "field 'cable.length'"),
    ("mass_per_length = 30.0", "mass_per_length = 2e-308", "field 'cable.mass_per_length'"),
    ("EA = 3.0e8", "EA = 1e-300", "field 'cable.EA'"),
    ("  mass = 15.0", "  mass = 1e300", "field 'setup[S].attachment[W1].mass'"),
])
def test_a_cable_value_beyond_any_cable_is_refused_not_left_to_the_solver(campaign, capsys, old, new, field):
    """These reached the solver and ended as 'natural frequencies did not converge' (exit 1)."""
    toml = edit(campaign, old, new)
    line = refusal(["forward", campaign], capsys)
    assert toml in line and field in line and "between" in line


@pytest.mark.parametrize("literal", ["1" * 5000, "[" * 5000 + "1" + "]" * 5000])
def test_a_campaign_file_past_the_parser_s_limits_is_refused_naming_it(campaign, capsys, literal):
    toml = edit(campaign, "EI = 2.0e5", f"EI = {literal}")
    line = refusal(["forward", campaign], capsys)
    assert toml in line and "not a valid TOML file" in line


def test_a_name_with_a_newline_stays_on_one_line(campaign, capsys):
    edit(campaign, 'name = "T1"', 'name = "T1\\nsecond line"')
    line = refusal(["forward", campaign, "--test", "T1"], capsys)
    assert "T1\\nsecond line" in line and "option '--test'" in line


@pytest.mark.parametrize("dataset, link, field", [
    ("acceleration", h5py.SoftLink("/nowhere"), "field 'acceleration'"),
    ("channel_position", h5py.SoftLink("/channel_position"), "field 'channel_position'"),
    ("acceleration", h5py.ExternalLink("/etc/passwd", "/acceleration"), "field 'acceleration'"),
])
def test_a_link_in_a_record_is_refused_naming_the_record_and_the_dataset(campaign, capsys, dataset, link, field):
    record = campaign / "records" / "T2.h5"
    with h5py.File(record, "r+") as h5:
        del h5[dataset]
        h5[dataset] = link
    line = refusal(["spectra", campaign], capsys)
    assert str(record) in line and field in line


@pytest.mark.parametrize("argv, option", [
    (["forward", "{c}", "--json", "{c}/campaign.toml"], "--json"),
    (["spectra", "{c}", "--json", "{c}/records/T2.h5"], "--json"),
    (["spectra", "{c}", "--plot", "{c}/records"], "--plot"),
    (["simulate", "{c}", "--out", "{c}", "--overwrite"], "--out"),
    (["simulate", "{c}", "--out", "{c}/campaign.toml/below"], "--out"),
    (["simulate", "{c}", "--out", "{c}/../sim", "--duration", "1e9"], "--duration"),
    (["simulate", "{c}", "--out", "{c}/../sim", "--impulses", "1000000"], "--impulses"),
    (["simulate", "{c}", "--out", "{c}/../sim", "--seed", "-1"], "--seed"),
    (["forward", "{c}", "--modes", str(2**62)], "--modes"),
    (["simulate", "{c}", "--out", "{c}/../sim", "--extra-mass", "5@99"], "--extra-mass"),
    (["simulate", "{c}", "--out", "{c}/../sim", "--impulses", "0"], "--impulses"),
    (["identify", "{c}", "--params", "tension,nope"], "--params"),
    (["diagnose", "{c}", "--effects", "wind"], "--effects"),
    (["forward", "{c}", "--test", "nope"], "--test"),
])
def test_an_option_that_would_harm_or_cannot_be_done_names_the_option(campaign, capsys, argv, option):
    before = {p: p.read_bytes() for p in campaign.rglob("*") if p.is_file()}
    line = refusal([a.format(c=campaign) for a in argv], capsys)
    assert f"option '{option}'" in line or f"argument {option}" in line
    assert {p: p.read_bytes() for p in campaign.rglob("*") if p.is_file()} == before


@pytest.mark.parametrize("rate, what", [(1e300, "must lie between"), (5.0, "below mode 1")])
def test_a_record_s_sampling_rate_beyond_use_names_the_record_and_the_field(campaign, capsys, rate, what):
    """1e300 Hz had ended deep in the spectra as "field 'f_max': must be > f_min", naming no file."""
    record = campaign / "records" / "T2.h5"
    with h5py.File(record, "r+") as h5:
        h5.attrs["sampling_rate"] = rate
    line = refusal(["spectra", campaign], capsys)
    assert str(record) in line and "field 'sampling_rate'" in line and what in line


def test_a_nyquist_alternating_record_ends_cleanly(campaign, capsys):
    """A record alternating at the Nyquist frequency once made the Whittle scoring step raise LinAlgError
    (a singular Fisher matrix): now the fit stops and the command ends with exit 0 or one clean line."""
    record = campaign / "records" / "T2.h5"
    with h5py.File(record, "r+") as h5:
        n = h5["acceleration"].shape[0]
        h5["acceleration"][...] = np.repeat(((-1.0) ** np.arange(n))[:, None], 2, axis=1)  # the fuzzer's case
    try:
        code = main(["spectra", str(campaign)])
    except SystemExit as exit_:
        code = exit_.code
    err = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("spectra: ")]
    assert code == 0 or (code in (1, 2) and len(err) == 1 and "Traceback" not in err[0]), (code, err)


@pytest.mark.parametrize("seed", range(6))
def test_a_record_with_flipped_bits_is_read_or_refused_naming_it(campaign, capsys, seed):
    """Bit flips anywhere in the HDF5 file (header, metadata or samples) had raised OSError, KeyError or
    RuntimeError from h5py: a flip either leaves a readable record or is refused naming the record."""
    record = campaign / "records" / "T2.h5"
    data = bytearray(record.read_bytes())
    rng = np.random.default_rng(seed)
    for i in rng.integers(0, len(data), 40):
        data[i] ^= 1 << int(rng.integers(8))
    record.write_bytes(bytes(data))
    try:
        code = main(["spectra", str(campaign)])
    except SystemExit as exit_:
        code = exit_.code
    err = [ln for ln in capsys.readouterr().err.splitlines()
           if not ln.startswith("spectra: ") and "warning" not in ln]
    assert code == 0 or (code == 2 and len(err) == 1 and str(record) in err[0]), (code, err)


HUGE = "1" + "0" * 400  # an integer TOML reads whole, beyond a float's range


@pytest.mark.parametrize("old, new, field, said", [
    ('boundary = "clamped"', f"boundary = {HUGE}", "field 'cable.boundary'", "too large"),
    ('boundary = "clamped"', f'boundary = ["clamped", {HUGE}]', "field 'cable.boundary'", "end B: is too large"),
    ('boundary = "clamped"', f'boundary = [{HUGE}, "pinned"]', "field 'cable.boundary'", "end A: is too large"),
    ("[tolerance]", f'[channels]\nA1 = {{ position = 2.0, direction = {HUGE} }}\n\n[tolerance]',
     "field 'channels.A1.direction'", "an integer beyond the range of a float"),
])
def test_an_integer_beyond_a_float_names_the_file_and_the_field(campaign, capsys, old, new, field, said):
    """Issue 34 (fuzz): an end stiffness (and a channel's direction) written as a huge TOML integer ended in
    an OverflowError; every other number of the campaign went through the shared check (tests/test_fuzz.py's
    huge_integer and huge_boundary kinds, and each number of a campaign with every field: none left)."""
    toml = edit(campaign, old, new)
    line = refusal(["forward", campaign], capsys)
    assert toml in line and field in line and said in line, line


NUL_RECORD = 'record = "records/a\\u0000b.h5"'  # TOML's escape: the path holds a NUL character


@pytest.mark.parametrize("command", [["forward"], ["spectra"], ["identify"], ["diagnose"],
                                     ["simulate", "--out", "{tmp}/sim"]])
def test_a_record_path_with_a_nul_names_the_file_and_the_field(campaign, capsys, tmp_path, command):
    """Issue 34 (fuzz): ValueError 'embedded null byte' from the output checks (os.path.realpath)."""
    toml = edit(campaign, 'record = "records/T2.h5"', NUL_RECORD)
    line = refusal([command[0], campaign, *(a.format(tmp=tmp_path) for a in command[1:])], capsys)
    assert toml in line and "field 'test[T2].record'" in line and "NUL" in line, line


def test_an_archive_whose_campaign_has_a_nul_record_path_is_refused(campaign, capsys, tmp_path):
    archive = tmp_path / "archive"
    (archive / "C1" / "records").mkdir(parents=True)
    text = (campaign / "campaign.toml").read_text().replace('record = "records/T2.h5"', NUL_RECORD)
    (archive / "C1" / "campaign.toml").write_text(text)
    line = refusal(["track", archive, "--out", tmp_path / "out"], capsys)
    assert str(archive / "C1" / "campaign.toml") in line and "field 'test[T2].record'" in line, line


@pytest.mark.parametrize("argv, named", [
    (["forward", "{c}", "--json", "{t}/a\0b.json"], "option '--json'"),
    (["spectra", "{c}", "--plot", "{t}/p\0q"], "option '--plot'"),
    (["identify", "{c}", "--test", "T1", "--json", "{t}/a\0b.json"], "option '--json'"),
    (["simulate", "{c}", "--out", "{t}/s\0m"], "option '--out'"),
    (["forward", "{c}\0x"], "\\x00x"),
    (["track", "{t}/arch\0x"], "\\x00x"),
    (["tension", "--length", "8", "--mass", "30", "--frequencies", "12.3", "--json", "{t}/a\0b.json"],
     "option '--json'"),
])
def test_a_path_with_a_nul_on_the_command_line_is_refused(campaign, capsys, tmp_path, argv, named):
    """A shell cannot pass a NUL in an argument, main(argv) in-process can: one line, never 'embedded null
    byte' from the system's interface."""
    line = refusal([a.format(c=campaign, t=tmp_path) for a in argv], capsys)
    assert "holds a NUL character" in line and named in line, line
