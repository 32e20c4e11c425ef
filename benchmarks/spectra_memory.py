"""Memory and time of `stcs-ident spectra` on one large record: 50 channels × 2,000,000 float32 samples.

The record (400 MB of float32 on disk, 800 MB as float64) is written once
into a temporary campaign: the fuzzer's 8 m hanger with a clamp, at 200 Hz
(2.8 hours), its first modes as narrow-band responses common to every
channel (times each channel's mode shape), plus sensor noise. Then
``stcs-ident spectra`` runs on it in a child process (the installed
package's entry point), and this script prints the child's peak resident
memory against the bound of the reliability issue: twice the record's
float64 size plus a fixed overhead (the interpreter and its libraries,
measured as the peak of the same command on a record of 1000 samples).

With ``--baseline PYTHON`` (an interpreter with another stcs_ident installed,
the code before a change) the same command runs on the same record with that
installation too, in turns with this one (``--rounds`` each, default 1), and the
script prints both times and peaks, their ratios, and whether the two JSON
outputs hold the same modes.

Run from the repository root::

    python benchmarks/spectra_memory.py                      # the 50 × 2,000,000 record
    python benchmarks/spectra_memory.py --samples 200000     # a tenth of it, quicker
    python benchmarks/spectra_memory.py --baseline /tmp/venv-base/bin/python --rounds 2
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import h5py
import numpy as np
from common import print_header
from fuzz_inputs import BASE_TOML, _frequencies
from scipy import signal

LENGTH, TENSION = 8.0, 5.0e5  # the fuzz campaign's cable and its test T2


def write_record(path: Path, n_samples: int, n_channels: int, rate: float, seed: int = 0) -> None:
    """A field-like ambient record written in blocks of rows (never the whole array in memory)."""
    from stcs_ident.core.model import Attachment, Cable
    from stcs_ident.forward import batch_frequencies

    cable = Cable(length=LENGTH, mass_per_length=30.0, EI=2.0e5, EA=3.0e8, inclination=np.radians(10.0))
    f = np.asarray(batch_frequencies(cable, (Attachment("W1", 2.7, 15.0),), TENSION, 12)).ravel()
    f = f[f < 0.4 * rate]
    rng = np.random.default_rng(seed)
    x = np.linspace(0.05, 0.95, n_channels) * LENGTH
    shapes = np.sin(np.outer(np.arange(1, f.size + 1), np.pi * x / LENGTH))  # (modes, channels)
    zeta = 0.005
    filters = []
    for fn in f:  # a resonator per mode, driven by white noise: its modal response
        w = 2 * np.pi * fn / rate
        r = np.exp(-zeta * w)
        filters.append(([1.0], [1.0, -2 * r * np.cos(w * np.sqrt(1 - zeta**2)), r * r]))
    states = [np.zeros(2) for _ in f]
    block = 200_000
    with h5py.File(path, "w") as h5:
        h5.attrs.update(format="stcs-record", version=1, sampling_rate=rate, unit="m/s^2")
        data = h5.create_dataset("acceleration", shape=(n_samples, n_channels), dtype=np.float32)
        h5.create_dataset("channel_name", data=[f"A{k + 1}" for k in range(n_channels)], dtype=h5py.string_dtype())
        h5["channel_position"] = x
        for start in range(0, n_samples, block):
            n = min(block, n_samples - start)
            q = np.empty((f.size, n))
            for k, (b, a) in enumerate(filters):
                q[k], states[k] = signal.lfilter(b, a, rng.standard_normal(n), zi=states[k])
            acc = (q / np.arange(1, f.size + 1)[:, None]).T @ shapes
            acc += 0.1 * acc.std() * rng.standard_normal(acc.shape)
            data[start:start + n] = acc.astype(np.float32)


def campaign(directory: Path, n_samples: int, n_channels: int, rate: float) -> Path:
    (directory / "records").mkdir(parents=True)
    (directory / "campaign.toml").write_text(BASE_TOML.format(f=_frequencies()), encoding="utf-8")
    write_record(directory / "records" / "T2.h5", n_samples, n_channels, rate)
    return directory


def run_spectra(directory: Path, python: str = sys.executable,
                output: Path | None = None) -> tuple[int, float, float, str, float]:
    """Exit status, wall time (s), peak resident memory (MB), standard error and CPU time (s, user + system:
    what a busy machine inflates least) of ``stcs-ident spectra`` run by ``python`` in a child process (its
    peak and CPU alone, from wait4); its JSON output in ``output`` (default beside the campaign)."""
    output = directory.parent / f"{directory.name}.json" if output is None else output
    command = [python, "-c", "import sys; from stcs_ident.cli.main import main; sys.exit(main(sys.argv[1:]))",
               "spectra", str(directory), "--test", "T2", "--json", str(output)]
    with tempfile.TemporaryFile("w+") as err:
        started = time.perf_counter()
        # Not run from the checkout (its source tree would shadow the baseline's installed package).
        child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err, text=True, cwd=directory.parent)
        _, status, usage = os.wait4(child.pid, 0)
        elapsed = time.perf_counter() - started
        err.seek(0)
        return (os.waitstatus_to_exitcode(status), elapsed, usage.ru_maxrss / 1024, err.read(),
                usage.ru_utime + usage.ru_stime)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2_000_000)
    parser.add_argument("--channels", type=int, default=50)
    parser.add_argument("--rate", type=float, default=200.0, help="sampling rate, Hz (default 200)")
    parser.add_argument("--baseline", metavar="PYTHON", help="also run the command with this Python's stcs_ident")
    parser.add_argument("--rounds", type=int, default=1, help="with --baseline: runs of each, in turns (default 1)")
    args = parser.parse_args(argv)
    print_header()
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        big = campaign(Path(tmp) / "big", args.samples, args.channels, args.rate)
        size = (big / "records" / "T2.h5").stat().st_size
        print(f"record: {args.channels} channels x {args.samples} samples float32 at {args.rate:g} Hz, "
              f"{size / 1e6:.0f} MB on disk, written in {time.perf_counter() - started:.0f} s", flush=True)
        overhead = run_spectra(campaign(Path(tmp) / "small", 4096, args.channels, args.rate))[2]
        code, elapsed, peak, err, cpu = run_spectra(big)
        if args.baseline:
            compare_baseline(big, args.baseline, max(1, args.rounds), (code, elapsed, peak, cpu))
    float64 = args.samples * args.channels * 8 / 2**20
    bound = 2 * float64 + overhead
    print(f"fixed overhead (the same command on 4096 samples): {overhead:.0f} MB")
    print(f"spectra on the record: {elapsed:.1f} s ({cpu:.1f} s of CPU), peak resident memory {peak:.0f} MB; bound 2 x {float64:.0f} MB "
          f"(float64 size) + {overhead:.0f} MB = {bound:.0f} MB: {'within' if peak <= bound else 'EXCEEDED'} "
          f"({peak / float64:.2f} x the float64 size)")
    if code != 0:
        print(f"exit status {code}:", *err.strip().splitlines()[-3:], sep="\n  ")
    return 0 if peak <= bound and code == 0 else 1


def compare_baseline(big: Path, baseline: str, rounds: int, first: tuple[int, float, float, float]) -> None:
    """This code's and the ``baseline`` Python's command on the same record, in turns (``first``: this code's
    run already made); times, peaks, their ratios and whether both report the same modes."""
    import json
    import statistics

    ours, theirs = [first], []
    out = {"this": big.parent / f"{big.name}.json", "baseline": big.parent / "baseline.json"}
    for k in range(rounds):
        theirs.append(_kept(run_spectra(big, baseline, out["baseline"])))
        if k + 1 < rounds:
            ours.append(_kept(run_spectra(big)))
    load = os.getloadavg()[0]
    print(f"this code and the baseline ({baseline}), {rounds} run{'s' if rounds > 1 else ''} each in turns, "
          f"load average {load:.2f} at the end:")
    for label, runs in (("this code", ours), ("baseline", theirs)):
        times, peaks, cpus = [r[1] for r in runs], [r[2] for r in runs], [r[3] for r in runs]
        failed = [r[0] for r in runs if r[0] != 0]
        print(f"  {label:9}: {', '.join(f'{t:.1f}' for t in times)} s (median {statistics.median(times):.1f}), "
              f"CPU {', '.join(f'{c:.1f}' for c in cpus)} s, peak {', '.join(f'{p:.0f}' for p in peaks)} MB"
              + (f"; exit status {failed}" if failed else ""))
    ratio_t = statistics.median(r[1] for r in ours) / statistics.median(r[1] for r in theirs)
    ratio_c = statistics.median(r[3] for r in ours) / statistics.median(r[3] for r in theirs)
    ratio_m = max(r[2] for r in ours) / max(r[2] for r in theirs)
    print(f"  this code / baseline: time {ratio_t:.2f}, CPU time {ratio_c:.2f} (medians), peak memory "
          f"{ratio_m:.2f} (largest)")
    try:
        mine, before = (json.loads(out[key].read_text(encoding="utf-8"))["tests"] for key in ("this", "baseline"))
    except (OSError, ValueError, KeyError) as err:
        print(f"  outputs not compared: {err}")
        return
    print(f"  modes: {modes_compared(mine, before)}")


def _kept(run: tuple) -> tuple[int, float, float, float]:
    """Exit status, wall time, peak and CPU time of a :func:`run_spectra` run."""
    code, elapsed, peak, _, cpu = run
    return code, elapsed, peak, cpu


def modes_compared(mine: list, before: list) -> str:
    """The two JSON outputs' tests' modes: the same count and numbers, and the largest |Δf| / 1σ."""
    worst, count = 0.0, 0
    for a, b in zip(mine, before):
        if a.get("modes") != b.get("modes") or len(a["frequencies"]) != len(b["frequencies"]):
            return f"test {a.get('name')}: modes {a.get('modes')} against the baseline's {b.get('modes')}"
        for f, u, g in zip(a["frequencies"], a["uncertainty"], b["frequencies"]):
            worst, count = max(worst, abs(f - g) / u), count + 1
    return f"the same {count} numbered modes, frequencies within {worst:.1e} of their 1σ"


if __name__ == "__main__":
    raise SystemExit(main())
