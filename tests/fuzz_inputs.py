"""A seeded fuzzer of the command line: mutated campaign files, records and options.

Every generated case is a campaign directory (``campaign.toml``, a short
record) and a command line. :func:`run_case` runs it in-process through
``stcs_ident.cli.main.main`` under a time limit and classifies the outcome:

- ``ok``: exit 0;
- ``refused``: exit 2 with one line on standard error that names the
  mutated file and its field (``stcs-ident: <file>: field '<field>': ...``;
  for a file that does not parse at all, the file and what is wrong with
  it), or, for an option, the option;
- ``failed``: exit 1 with one line;
- anything else is a finding: ``traceback`` (an exception escaped),
  ``hang`` (over the time limit), ``modified`` (an input file changed or
  disappeared), ``multiline`` (the message is not one line), ``unnamed``
  (exit 2 not naming them), ``exit`` (another status),
  ``bad_json`` (a successful run wrote a JSON file that is not standard
  JSON: NaN or Infinity).

A seeded generator of our own rather than hypothesis: the inputs are files
on disk and command lines whose mutations are domain-specific (HDF5 links,
TOML nesting, numbers past float range), and the long run needs a plain
reproducible stream (case k of seed s) more than shrinking.
Used by tests/test_fuzz.py (a bounded seeded run) and benchmarks/fuzz.py
(the long run).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import json
import os
import random
import re
import shutil
import signal
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

#: The campaign every case mutates: a hanger with a clamp, two tests (one with a record).
BASE_TOML = """[campaign]
name = "fuzz"
description = "seeded fuzz case"

[cable]
length = 8.0
mass_per_length = 30.0
EI = 2.0e5
EA = 3.0e8
inclination = 10.0
boundary = "clamped"

[tolerance]
tension = 0.02

[[setup]]
name = "S"
  [[setup.attachment]]
  name = "W1"
  position = 2.7
  mass = 15.0

[[test]]
name = "T1"
setup = "S"
tension = 4.0e5
frequencies = [{f}]

[[test]]
name = "T2"
setup = "S"
tension = 5.0e5
record = "records/T2.h5"
"""

#: Mutation kinds of the campaign file, the record and the command line.
TOML_KINDS = ("delete_line", "duplicate_line", "swap_lines", "truncate", "random_bytes", "not_utf8",
              "huge_integer", "long_literal", "float_overflow", "nonfinite", "negative", "zero", "tiny",
              "string_for_number", "number_for_string", "nested_arrays", "control_name", "newline_name",
              "long_name", "unknown_key", "many_attachments", "empty_file", "many_tests", "bad_boundary",
              "huge_mode", "reference_huge", "extreme_frequencies", "huge_boundary", "nul_record")
RECORD_KINDS = ("bit_flips", "truncated_record", "dangling_link", "self_link", "external_link", "wrong_dtype",
                "wrong_shape", "nan_samples", "nyquist", "missing_dataset", "empty_record", "not_hdf5",
                "string_rate", "huge_rate", "one_sample", "constant")
OPTION_KINDS = ("modes_huge", "modes_negative", "json_is_input", "json_is_record", "plot_is_records",
                "out_is_campaign", "json_missing_dir", "unknown_test", "bad_params", "bad_effects",
                "simulate_bad_seed", "simulate_bad_extra_mass", "simulate_bad_end_stiffness",
                "simulate_long_duration", "simulate_many_impulses", "simulate_out_is_file")
KINDS = TOML_KINDS + RECORD_KINDS + OPTION_KINDS


@dataclass
class Case:
    """One generated input: where it lives, what was mutated, the command line."""

    seed: int
    index: int
    kind: str
    directory: Path
    argv: list[str]


@dataclass
class Outcome:
    case: Case
    status: str
    code: int | None
    stderr: str


@functools.lru_cache(maxsize=1)
def _frequencies() -> str:
    """The base campaign's first test: 5 frequencies of the nominal model."""
    from stcs_ident.core.model import Attachment, Cable
    from stcs_ident.forward import batch_frequencies

    cable = Cable(length=8.0, mass_per_length=30.0, EI=2.0e5, EA=3.0e8, inclination=np.radians(10.0))
    f = batch_frequencies(cable, (Attachment("W1", 2.7, 15.0),), 4.0e5, 5)
    return ", ".join(f"{x:.4f}" for x in np.asarray(f).ravel())


def _record(path: Path, rng: np.random.Generator, n: int = 2048, rate: float = 256.0) -> None:
    t = np.arange(n) / rate
    acc = np.stack([np.sin(2 * np.pi * 12.3 * t) * np.exp(-0.05 * t) + 0.01 * rng.standard_normal(n)
                    for _ in range(2)], axis=1)
    with h5py.File(path, "w") as h5:
        h5.attrs.update(format="stcs-record", version=1, sampling_rate=rate, unit="m/s^2")
        h5["acceleration"] = acc
        h5.create_dataset("channel_name", data=["A1", "A2"], dtype=h5py.string_dtype())
        h5["channel_position"] = np.array([2.0, 4.1])


_NUMBER = re.compile(r"(?<![\w.\-])(-?\d+(?:\.\d+)?(?:e[+-]?\d+)?)(?![\w.])")


def _mutate_toml(text: str, kind: str, rng: random.Random) -> str | bytes:
    lines = text.splitlines()
    numbers = list(_NUMBER.finditer(text))

    def replace_number(new: str) -> str:
        m = rng.choice(numbers)
        return text[:m.start()] + new + text[m.end():]

    if kind == "delete_line":
        del lines[rng.randrange(len(lines))]
    elif kind == "duplicate_line":
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
    elif kind == "swap_lines":
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == "truncate":
        return text[:rng.randrange(len(text))]
    elif kind == "random_bytes":
        data = bytearray(text.encode())
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(len(data))] = rng.randrange(256)
        return bytes(data)
    elif kind == "not_utf8":
        return text.encode("utf-16")
    elif kind == "huge_integer":
        return replace_number(str(10 ** rng.choice((19, 309, 400, 4000))))
    elif kind == "long_literal":
        return replace_number("1" * rng.choice((5000, 20000)) + ".0")
    elif kind == "float_overflow":
        return replace_number(rng.choice(("1e308", "1.7e308", "1e309", "-1e309", "1e-320", "5e-324")))
    elif kind == "nonfinite":
        return replace_number(rng.choice(("nan", "inf", "-inf", "+nan")))
    elif kind == "negative":
        return replace_number("-" + rng.choice(numbers).group(1).lstrip("-"))
    elif kind == "zero":
        return replace_number(rng.choice(("0", "0.0", "-0.0")))
    elif kind == "tiny":
        return replace_number(rng.choice(("1e-300", "1e-12", "2e-308")))
    elif kind == "string_for_number":
        return replace_number(rng.choice(('"abc"', '"1.0"', "true", "[1.0]", "{a = 1}", '""')))
    elif kind == "number_for_string":
        new = rng.choice(("12", "1.5", "[]", "true"))
        return re.sub(r'"[^"\n]*"', lambda m: new, text, count=rng.randint(1, 3))
    elif kind == "nested_arrays":
        depth = rng.choice((50, 500, 5000))
        return replace_number("[" * depth + "1" + "]" * depth)
    elif kind in ("control_name", "newline_name", "long_name"):
        new = {"control_name": '"T\\u0007\\u001b[31m1"', "newline_name": '"T1\\nsecond line"',
               "long_name": '"' + "x" * 100000 + '"'}[kind]
        return text.replace('name = "T1"', f"name = {new}")
    elif kind == "unknown_key":
        i = rng.randrange(len(lines))
        lines.insert(i + 1, rng.choice(("colour = 3", "lenght = 8.0", "[extra]", "x.y = 1")))
    elif kind == "many_attachments":
        n = rng.choice((200, 2000))
        extra = "".join(f"\n  [[setup.attachment]]\n  name = \"M{k}\"\n  position = {0.001 + 7.99 * k / n:.6f}\n"
                        f"  mass = 0.1\n" for k in range(n))
        return text.replace('  mass = 15.0\n', '  mass = 15.0\n' + extra, 1)
    elif kind == "empty_file":
        return rng.choice(("", "\n", "[campaign]\n"))
    elif kind == "many_tests":
        n = rng.choice((100, 1000))
        extra = "".join(f'\n[[test]]\nname = "X{k}"\nsetup = "S"\ntension = 4.0e5\nfrequencies = [1.0]\n'
                        for k in range(n))
        return text + extra
    elif kind == "huge_mode":
        return text.replace("frequencies = [", f"modes = [1, 2, 3, 4, {rng.choice((2**62, 10**6, 10**30))}]\n"
                                              "frequencies = [", 1)
    elif kind == "reference_huge":
        return text.replace("frequencies = [", "reference = {paper = [" + ", ".join(
            [rng.choice(("1e300", "1.7e308", "1e-300", "0.0", "-5.0"))] * 5) + "]}\nfrequencies = [", 1)
    elif kind == "extreme_frequencies":
        value = rng.choice(("1e-300", "1e300", "1e-12", "1e12"))
        return re.sub(r"frequencies = \[[^\]]*\]", lambda m: f"frequencies = [{value}, 2.0, 3.0, {value}, 5.0]",
                      text, count=1)
    elif kind == "huge_boundary":  # an end stiffness as an integer beyond a float (alone, or one end of two)
        huge = str(10 ** rng.choice((309, 400, 4000)))
        return text.replace('boundary = "clamped"', "boundary = " + rng.choice(
            (huge, f'["clamped", {huge}]', f'[{huge}, "pinned"]', f"[{huge}, {huge}]")))
    elif kind == "nul_record":  # a NUL character in a record's path (the system refuses such a path)
        return text.replace('record = "records/T2.h5"', 'record = ' + rng.choice(
            ('"records/a\\u0000b.h5"', '"records/T2.h5\\u0000"', '"\\u0000"')))
    elif kind == "bad_boundary":
        return text.replace('boundary = "clamped"', "boundary = " + rng.choice(
            ('"glued"', "[1, 2, 3]", "-5.0", "nan", '["clamped"]', "1e400", "[]")))
    return "\n".join(lines) + "\n"


def _mutate_record(path: Path, kind: str, rng: random.Random) -> None:
    if kind == "bit_flips":
        data = bytearray(path.read_bytes())
        for _ in range(rng.randint(1, 40)):
            i = rng.randrange(len(data))
            data[i] ^= 1 << rng.randrange(8)
        path.write_bytes(bytes(data))
    elif kind == "truncated_record":
        data = path.read_bytes()
        path.write_bytes(data[:rng.randrange(len(data))])
    elif kind == "not_hdf5":
        path.write_bytes(rng.choice((b"", b"time,A1\n0,1\n", bytes(rng.randrange(256) for _ in range(600)))))
    else:
        with h5py.File(path, "r+") as h5:
            if kind == "dangling_link":
                del h5["acceleration"]
                h5["acceleration"] = h5py.SoftLink("/nowhere")
            elif kind == "self_link":
                del h5["channel_position"]
                h5["channel_position"] = h5py.SoftLink("/channel_position")
            elif kind == "external_link":
                del h5["acceleration"]
                h5["acceleration"] = h5py.ExternalLink(rng.choice(("/etc/passwd", "missing.h5", "T2.h5")),
                                                       "/acceleration")
            elif kind == "wrong_dtype":
                data = h5["acceleration"][()]
                del h5["acceleration"]
                h5["acceleration"] = rng.choice((data.astype(np.int16), data.astype(np.complex64),
                                                 np.array([b"abc"] * 4), data.astype(np.float16)))
            elif kind == "wrong_shape":
                data = h5["acceleration"][()]
                del h5["acceleration"]
                h5["acceleration"] = rng.choice((data[:, 0], data[None], data.T, data[:, :1]))
            elif kind == "nan_samples":
                data = h5["acceleration"][()]
                data[rng.randrange(data.shape[0]), rng.randrange(2)] = rng.choice((np.nan, np.inf))
                h5["acceleration"][...] = data
            elif kind == "nyquist":
                n = h5["acceleration"].shape[0]
                h5["acceleration"][...] = np.repeat(((-1.0) ** np.arange(n))[:, None], 2, axis=1)
            elif kind == "missing_dataset":
                del h5[rng.choice(("acceleration", "channel_name", "channel_position"))]
            elif kind == "empty_record":
                del h5["acceleration"]
                h5["acceleration"] = np.zeros((0, 2))
            elif kind == "string_rate":
                h5.attrs["sampling_rate"] = rng.choice(("fast", "256", np.array([1.0, 2.0])))
            elif kind == "huge_rate":
                h5.attrs["sampling_rate"] = rng.choice((1e300, 1e-300, -256.0, np.inf, np.nan, 0.0))
            elif kind == "one_sample":
                del h5["acceleration"]
                h5["acceleration"] = np.zeros((1, 2))
            elif kind == "constant":
                h5["acceleration"][...] = 1.0


def _option_argv(kind: str, directory: Path, out: Path, rng: random.Random) -> list[str]:
    c = str(directory)
    toml = str(directory / "campaign.toml")
    record = str(directory / "records" / "T2.h5")
    return {
        "modes_huge": ["forward", c, "--modes", str(rng.choice((10**8, 2**62, 10**30)))],
        "modes_negative": ["forward", c, "--modes", rng.choice(("-3", "0"))],
        "json_is_input": [rng.choice(("forward", "identify")), c, "--test", "T1", "--json", toml],
        "json_is_record": ["spectra", c, "--json", record],
        "plot_is_records": ["spectra", c, "--plot", str(directory / "records")],
        "out_is_campaign": ["simulate", c, "--out", c, "--overwrite", "--duration", "2"],
        "json_missing_dir": ["forward", c, "--json", str(out / "no" / "such" / "dir" / "x.json")],
        "unknown_test": ["forward", c, "--test", rng.choice(("nope", "T1\nT2", ""))],
        "bad_params": ["identify", c, "--test", "T1", "--params",
                       rng.choice(("tension,EI,", "position[nope]", "EI,EI", "x" * 5000, "tension,position"))],
        "bad_effects": ["diagnose", c, "--test", "T1", "--effects", rng.choice(("nope", ",", "tension,,EI"))],
        "simulate_bad_seed": ["simulate", c, "--out", str(out / "sim"), "--seed", rng.choice(("-1", "2**70", "x"))],
        "simulate_bad_extra_mass": ["simulate", c, "--out", str(out / "sim"), "--extra-mass",
                                    rng.choice(("abc@1", "1@", "@2", "1@99", "-1@2", "nan@2"))],
        "simulate_bad_end_stiffness": ["simulate", c, "--out", str(out / "sim"), "--end-stiffness",
                                       rng.choice(("a,b", "1", "1,2,3", "-1,2", "nan,1"))],
        "simulate_long_duration": ["simulate", c, "--out", str(out / "sim"), "--duration",
                                   rng.choice(("1e9", "1e300", "inf", "-1", "0"))],
        "simulate_many_impulses": ["simulate", c, "--out", str(out / "sim"), "--impulses",
                                   rng.choice(("1000000", "-1", "1e3"))],
        "simulate_out_is_file": ["simulate", c, "--out", rng.choice((toml, record, toml + "/below"))],
    }[kind]


def make_case(seed: int, index: int, root: Path, kind: str | None = None) -> Case:
    """Case ``index`` of ``seed``: a fresh campaign directory under ``root`` with one mutation."""
    rng = random.Random(f"{seed}:{index}")
    kind = kind or KINDS[rng.randrange(len(KINDS))]
    directory = root / f"case-{seed}-{index}"
    if directory.exists():
        shutil.rmtree(directory)
    (directory / "records").mkdir(parents=True)
    out = root / f"out-{seed}-{index}"
    if out.exists():
        shutil.rmtree(out)
    out.mkdir()
    text = BASE_TOML.format(f=_frequencies())
    _record(directory / "records" / "T2.h5", np.random.default_rng(index))
    command = rng.choice(("forward", "spectra", "identify"))
    if kind in TOML_KINDS:
        text = _mutate_toml(text, kind, rng)
        if kind == "extreme_frequencies":
            command = rng.choice(("identify", "diagnose"))
        argv = [command, str(directory)] + (["--test", "T1"] if command in ("identify", "diagnose") else [])
    elif kind in RECORD_KINDS:
        _mutate_record(directory / "records" / "T2.h5", kind, rng)
        argv = ["spectra", str(directory)]
    else:
        argv = _option_argv(kind, directory, out, rng)
    path = directory / "campaign.toml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8", "surrogatepass"))
    if kind in TOML_KINDS and rng.random() < 0.3:
        argv += ["--json", str(out / "result.json")]
    return Case(seed, index, kind, directory, argv)


def _digest(directory: Path) -> dict[str, str]:
    return {str(p.relative_to(directory)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(directory.rglob("*")) if p.is_file()}


class _Timeout(Exception):
    pass


def run_case(case: Case, time_limit: float = 30.0) -> Outcome:
    """Run ``case`` in-process; classify its outcome (see the module docstring)."""
    from stcs_ident.cli.main import main

    before = _digest(case.directory)
    err, out = io.StringIO(), io.StringIO()

    def alarm(signum, frame):
        raise _Timeout

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, time_limit)
    code: int | None = None
    status = None
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            try:
                code = main(case.argv)
            except SystemExit as exit_:  # argparse's own refusals
                code = exit_.code if isinstance(exit_.code, int) else 2
    except _Timeout:
        status = "hang"
    except BaseException:  # noqa: BLE001 (any escaping exception is the finding)
        import traceback

        err.write(traceback.format_exc())
        status = "traceback"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    text = err.getvalue()
    after = _digest(case.directory)
    changed = {k for k in before if after.get(k) != before[k]}
    if status is None:
        lines = [ln for ln in text.splitlines() if not ln.startswith(("diagnose: ", "spectra: ", "simulate: "))
                 and "warning" not in ln]
        if changed:
            status = "modified"
        elif code == 0 and not _strict_json(case.argv):
            status = "bad_json"
        elif code == 0:
            status = "ok"
        elif code in (1, 2) and len(lines) != 1:
            status = "multiline"
        elif code == 2 and not _names_what(case, lines[0]):
            status = "unnamed"
        elif code == 2:
            status = "refused"
        elif code == 1:
            status = "failed"
        else:
            status = "exit"
    elif changed and status != "traceback":
        status = "modified"
    return Outcome(case, status, code, text)


#: Refusals about a whole file, where no field exists: its syntax, its encoding, its container.
FILE_LEVEL = ("not a valid TOML file", "not a TOML file", "not an HDF5 file", "cannot read the file")


def _names_what(case: Case, line: str) -> bool:
    """Whether a refusal names what is wrong: the mutated file and its field (or, for a file that cannot be
    parsed at all, the file and what is wrong with it), or the option."""
    if case.kind in OPTION_KINDS:
        return "option '--" in line or "argument --" in line
    file = case.directory / ("campaign.toml" if case.kind in TOML_KINDS else "records/T2.h5")
    if str(file) not in line:
        return False
    return "field '" in line or "option '--" in line or any(s in line for s in FILE_LEVEL)


FINDINGS = ("traceback", "hang", "modified", "multiline", "unnamed", "exit", "bad_json")


def _strict_json(argv: list[str]) -> bool:
    """Whether the ``--json`` file a successful run wrote (if any) is standard JSON (no NaN or Infinity)."""
    if "--json" not in argv:
        return True
    path = Path(argv[argv.index("--json") + 1])
    if not path.is_file():
        return False

    def refuse(constant):
        raise ValueError(constant)

    try:
        json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)
    except ValueError:
        return False
    return True


def run(seed: int, n: int, root: Path, time_limit: float = 30.0, progress=None) -> list[Outcome]:
    """``n`` cases of ``seed`` (kinds in turn, so that every kind is tried), each directory removed after."""
    outcomes = []
    for k in range(n):
        case = make_case(seed, k, root, KINDS[k % len(KINDS)])
        outcomes.append(run_case(case, time_limit))
        shutil.rmtree(case.directory, ignore_errors=True)
        shutil.rmtree(root / f"out-{seed}-{k}", ignore_errors=True)
        if progress is not None:
            progress(k + 1, n, outcomes[-1])
    return outcomes


if __name__ == "__main__":  # pragma: no cover
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        for o in run(int(sys.argv[1]), int(sys.argv[2]), Path(tmp)):
            if o.status in FINDINGS:
                print(o.case.kind, o.status, o.code, o.case.argv[:4], o.stderr.strip().splitlines()[-1:])
    os._exit(0)


def write_base_campaign(directory):
    """The base campaign (a hanger with a clamp; T1 a table, T2 a record) written into ``directory``."""
    (directory / "records").mkdir(parents=True)
    (directory / "campaign.toml").write_text(BASE_TOML.format(f=_frequencies()), encoding="utf-8")
    _record(directory / "records" / "T2.h5", np.random.default_rng(0))
    return directory
