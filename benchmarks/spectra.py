"""Modal frequency estimation benchmark: stcs_ident's find_peaks against pyOMA-2 FDD and EFDD, side by side.

Every method sees the SAME simulated records (seeded modal superposition of
the exact cable model, ``stcs_ident.simulate.simulate_record``):

- a short stiff hanger (l = 8 m, m = 30 kg/m, EI = 2e5 N m², H = 400 kN,
  clamped), 3 sensors, ζ = 0.8 %, SNR 20 dB;
- a long inclined stay with sag (l = 120 m, m = 60 kg/m, EI = 2e6 N m²,
  EA = 3e9 N, 30°, H = 4 MN, a 50 kg damper-like mass 3 m from the lower
  anchorage), 4 sensors, ζ = 0.3 %, SNR 26 dB;

each as ambient records (10 min, uncorrelated or correlated random pressure)
and as hand-excitation records (impulses at rest, sensor noise only). Per
mode the error is |f_est / f_true - 1|, the median over the seeded records
of a case; a mode our estimator does not report (no peak within 0.3 × the
distance to the neighbouring mode) counts as a miss.

pyOMA-2 is given a favourable setup: its peaks are picked at the TRUE
frequencies (``sel_freq`` = truth, search half-width DF = 0.3 × the
smallest mode spacing), ``nxseg`` is the smallest power of two whose
resolution reaches the half-power bandwidth 2ζf₁ of the first mode
(computed from the true ζ and f₁), capped so that Welch averages at least
3 segments, and EFDD's ``npmax`` is 40 peaks of the correlation function
(fewer only if the record cannot provide them). Our estimator is told
nothing: it detects and fits the peaks blind.

Throughput: a 16-sensor, 10-minute ambient record of the stay at 256 Hz
processed by find_peaks (target ≤ 0.5 s on two cores), and pyOMA FDD (spectral matrix,
SVD, peak picking at the true frequencies) on the same record.

pyOMA-2 is an optional, benchmark-only dependency: ``pip install pyoma-2``.

Wall times depend on what else runs on the machine: the per-mode fits make
hundreds of small least-squares solves, and with OpenBLAS's default threads
each one waits for a busy core, so a loaded machine can multiply
find_peaks' time several-fold. The throughput table therefore also gives
the minimum over the runs and, when ``threadpoolctl`` is importable (it
comes with pyOMA-2's scikit-learn), the time with BLAS limited to one
thread, and prints the load average.

Planes: ``python benchmarks/spectra.py --planes [--repeat N] [--baseline PYTHON]`` times
:func:`analyse_record` on biaxial records of the stay with deck modes (benchmarks/plane_records.py: 3
positions x in/out, 400 s at 12.8 Hz), read per plane (with their channel directions) and read as one plane
(the same records without them, as every record was read before the planes), and prints the seconds per
channel of each (minimum over N runs, default 5). With ``--baseline PYTHON`` (an interpreter with another
stcs_ident installed, e.g. ``python3 -m venv /tmp/venv-base && /tmp/venv-base/bin/pip install <checkout of
the code before the planes>``) the same records are pickled and timed by that code too
(benchmarks/time_records.py), and the ratios printed: the issue's baseline is the code before the planes,
which reads a biaxial record as one plane.

Run: ``python benchmarks/spectra.py [--quick]`` (about 1.5 minutes on two idle
cores; ``--quick``: one record per case, one timing repeat, about 25 s), or
``python benchmarks/spectra.py --throughput [--repeat N]`` for the find_peaks
throughput case alone (N runs, default 5; pyOMA-2 not needed).

``--throughput --baseline PYTHON`` times the same record (pickled) with the
stcs_ident of PYTHON too (the code before a change, installed in its own
environment), in turns with this code (``--rounds`` rounds of N runs each, default
2), and prints both, their ratio and whether the two codes report the same peaks
(the largest difference of a frequency over its 1σ).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import math
import os
import statistics
import sys
import time
from dataclasses import dataclass

import numpy as np
from common import print_header, wall_times

PYOMA_MISSING = (
    "pyOMA-2 is not installed; this benchmark compares against it.\n"
    "Install it (benchmark-only optional dependency) with:\n"
    "    pip install pyoma-2\n"
    "then run: python benchmarks/spectra.py [--quick]"
)

MATCH_FRACTION = 0.3  # a reported peak belongs to a mode if within this fraction of the nearest mode spacing
PYOMA_DF_FRACTION = 0.3  # FDD / EFDD search half-width, fraction of the smallest mode spacing
PYOMA_DF2_FRACTION = 0.45  # EFDD bell half-width, fraction of the smallest mode spacing
PYOMA_NPMAX = (40, 30, 20, 10)  # EFDD: correlation-function peaks used, first that the record allows
PYOMA_MIN_SEGMENTS = 3  # Welch segments (50 % overlap) at least
NONE_WITHIN = 0.01  # "best" column: no method within 1 % is "none"
THROUGHPUT_TARGET = 0.5  # s, find_peaks on 16 channels x 10 min at 256 Hz on two cores (issue 36; 2 s before it)


@dataclass(frozen=True)
class Structure:
    name: str
    description: str
    cable: object
    attachments: tuple
    tension: float
    positions: tuple
    damping: float
    snr_db: float
    n_modes: int  # modes reported (from the first)


@dataclass(frozen=True)
class Case:
    structure: Structure
    kind: str  # "ambient" or "hand"
    sampling_rate: float
    duration: float
    ambient: object | None
    impulses: tuple
    seeds: tuple

    @property
    def title(self) -> str:
        s = self.structure
        if self.kind == "ambient":
            excitation = "ambient"
        else:
            n = len(self.impulses)
            excitation = f"hand excitation, {n} impulse{'s' if n > 1 else ''}"
        return (f"{s.name} · {excitation} · {len(s.positions)} sensors, {self.duration:g} s at "
                f"{self.sampling_rate:g} Hz, ζ = {100 * s.damping:g} %, SNR {s.snr_db:g} dB, "
                f"{len(self.seeds)} record{'s' if len(self.seeds) > 1 else ''}")


def structures():
    from stcs_ident.core.model import Attachment, Cable

    hanger = Structure(
        name="hanger",
        description="l = 8 m, m = 30 kg/m, EI = 2e5 N m², H = 400 kN, clamped",
        cable=Cable(length=8.0, mass_per_length=30.0, EI=2.0e5),
        attachments=(),
        tension=4.0e5,
        positions=(1.1, 2.3, 3.7),
        damping=0.008,
        snr_db=20.0,
        n_modes=5,
    )
    stay = Structure(
        name="stay",
        description="l = 120 m, m = 60 kg/m, EI = 2e6 N m², EA = 3e9 N, 30°, H = 4 MN, 50 kg mass at 3 m",
        cable=Cable(length=120.0, mass_per_length=60.0, EI=2.0e6, EA=3.0e9, inclination=math.radians(30.0)),
        attachments=(Attachment("damper", 3.0, mass=50.0),),
        tension=4.0e6,
        positions=(5.0, 9.0, 14.0, 20.0),
        damping=0.003,
        snr_db=26.0,
        n_modes=10,
    )
    return hanger, stay


def cases(quick: bool) -> list[Case]:
    from stcs_ident.simulate.simulate import Ambient, Impulse

    hanger, stay = structures()
    n = 1 if quick else 5
    seeds = lambda base: tuple(range(base, base + n))
    return [
        Case(hanger, "ambient", 200.0, 600.0, Ambient(200.0), (), seeds(101)),
        Case(hanger, "hand", 200.0, 30.0, None,
             (Impulse(1.0, 1.6, 40.0), Impulse(11.0, 2.9, -30.0), Impulse(21.0, 1.2, 50.0)), seeds(201)),
        Case(stay, "ambient", 100.0, 600.0, Ambient(50.0, correlation_length=5.0), (), seeds(301)),
        Case(stay, "hand", 100.0, 120.0, None, (Impulse(2.0, 2.5, 200.0),), seeds(401)),
    ]


# ----------------------------------------------------------------------------------------------------------------
# the three estimators


def ours(record, truth: np.ndarray, spacing: np.ndarray):
    """find_peaks, blind; each true mode matched to the nearest reported peak (or NaN: missed)."""
    from stcs_ident.spectra.peaks import find_peaks

    result = find_peaks(record)
    found = np.array([p.frequency for p in result.peaks])
    sigma = np.array([p.uncertainty for p in result.peaks])
    f = np.full(truth.size, np.nan)
    s = np.full(truth.size, np.nan)
    for k, (ft, gap) in enumerate(zip(truth, spacing)):
        if found.size:
            j = int(np.argmin(np.abs(found - ft)))
            if abs(found[j] - ft) <= MATCH_FRACTION * gap:
                f[k], s[k] = found[j], sigma[j]
    return f, s, len(result.peaks), result.kind


def pyoma_nxseg(fs: float, n_samples: int, f1: float, zeta: float) -> int:
    """Smallest power of two resolving 2ζf₁, capped to keep PYOMA_MIN_SEGMENTS Welch segments (50 % overlap)."""
    want = 2 ** math.ceil(math.log2(fs / (2 * zeta * f1)))
    cap = 2 ** math.floor(math.log2(2 * n_samples / (PYOMA_MIN_SEGMENTS + 1)))
    return int(min(want, cap))


@contextlib.contextmanager
def quiet():
    """pyOMA-2 draws tqdm bars on stderr and logs at INFO: keep the table readable."""
    with contextlib.redirect_stderr(io.StringIO()):
        yield


def pyoma(record, truth: np.ndarray, nxseg: int, df: float, df2: float):
    """pyOMA-2 FDD and EFDD ('per' spectral density), peaks picked at the true frequencies."""
    from pyoma2.algorithms.fdd import EFDD, FDD
    from pyoma2.setup.single import SingleSetup

    setup = SingleSetup(record.acceleration, record.sampling_rate)
    setup.add_algorithms(FDD(name="FDD", nxseg=nxseg, method_SD="per"),
                         EFDD(name="EFDD", nxseg=nxseg, method_SD="per"))
    with quiet():
        setup.run_all()
        setup.mpe("FDD", sel_freq=list(truth), DF=df)
        f_fdd = np.asarray(setup["FDD"].result.Fn, dtype=float)
        f_efdd, npmax_used = np.full(truth.size, np.nan), None
        for npmax in PYOMA_NPMAX:
            try:
                setup.mpe("EFDD", sel_freq=list(truth), DF1=df, DF2=df2, npmax=npmax)
            except ValueError:  # "Only N peaks found; Reduce npmax"
                continue
            f_efdd, npmax_used = np.asarray(setup["EFDD"].result.Fn, dtype=float), npmax
            break
    return f_fdd, f_efdd, npmax_used


# ----------------------------------------------------------------------------------------------------------------
# the comparison


def true_frequencies(structure: Structure, n: int) -> np.ndarray:
    from stcs_ident.forward import natural_frequencies

    return np.asarray(natural_frequencies(structure.cable, list(structure.attachments), structure.tension, n))


def simulate(case: Case, seed: int, positions=None, sampling_rate=None):
    from stcs_ident.simulate.simulate import simulate_record

    s = case.structure
    return simulate_record(
        s.cable, list(s.attachments), s.tension, list(positions or s.positions),
        duration=case.duration, sampling_rate=sampling_rate or case.sampling_rate, damping=s.damping,
        impulses=case.impulses, ambient=case.ambient, snr_db=s.snr_db, seed=seed,
    )


def run_case(case: Case) -> dict:
    s = case.structure
    f_all = true_frequencies(s, s.n_modes + 1)
    truth = f_all[: s.n_modes]
    gaps = np.diff(f_all)
    spacing = np.minimum(np.r_[np.inf, gaps[: s.n_modes - 1]], gaps[: s.n_modes])  # to the nearest mode
    n_samples = round(case.duration * case.sampling_rate)
    nxseg = pyoma_nxseg(case.sampling_rate, n_samples, truth[0], s.damping)
    df, df2 = PYOMA_DF_FRACTION * spacing.min(), PYOMA_DF2_FRACTION * spacing.min()
    errors = {"ours": [], "FDD": [], "EFDD": []}
    signed = {"ours": [], "FDD": [], "EFDD": []}
    z_scores, kinds, n_peaks, npmax_used, times = [], set(), [], set(), {"ours": 0.0, "pyOMA": 0.0}
    for seed in case.seeds:
        record = simulate(case, seed)
        t = time.perf_counter()
        f_ours, sigma, n_found, kind = ours(record, truth, spacing)
        times["ours"] += time.perf_counter() - t
        t = time.perf_counter()
        f_fdd, f_efdd, npmax = pyoma(record, truth, nxseg, df, df2)
        times["pyOMA"] += time.perf_counter() - t
        for name, f in (("ours", f_ours), ("FDD", f_fdd), ("EFDD", f_efdd)):
            errors[name].append(np.abs(f / truth - 1))
            signed[name].append(f / truth - 1)
        z_scores.append(np.abs(f_ours - truth) / sigma)
        kinds.add(kind)
        n_peaks.append(n_found)
        npmax_used.add(npmax)
    errors = {k: np.array(v) for k, v in errors.items()}  # (n_records, n_modes), NaN = missed / failed
    return {
        "case": case, "truth": truth, "nxseg": nxseg, "df": df, "df2": df2, "errors": errors,
        "signed": {k: np.array(v) for k, v in signed.items()}, "z": np.array(z_scores), "kinds": kinds,
        "n_peaks": n_peaks, "npmax": npmax_used, "times": times,
    }


def median_missing_as_inf(values: np.ndarray, axis=None):
    """Median with a miss (NaN) counted as the worst possible error."""
    return np.median(np.where(np.isnan(values), np.inf, values), axis=axis)


def fmt_err(e: float) -> str:
    return "miss" if not np.isfinite(e) else f"{e:.1e}"


def print_case(r: dict) -> dict:
    case, truth, errors = r["case"], r["truth"], r["errors"]
    s = case.structure
    n_rec = len(case.seeds)
    per_mode = {k: median_missing_as_inf(v, axis=0) for k, v in errors.items()}
    found = np.sum(~np.isnan(errors["ours"]), axis=0)
    z = np.array([np.median(col[~np.isnan(col)]) if np.any(~np.isnan(col)) else np.nan for col in r["z"].T])
    print(f"\n{case.title}")
    print(f"  {s.description}; find_peaks saw kind = {'/'.join(sorted(r['kinds']))}, "
          f"reported {min(r['n_peaks'])}-{max(r['n_peaks'])} peaks per record")
    npmax = ", ".join(str(n) for n in sorted(r["npmax"], key=lambda n: -1 if n is None else n))
    print(f"  pyOMA: nxseg = {r['nxseg']} (df = {case.sampling_rate / r['nxseg']:.4f} Hz), method_SD = 'per', "
          f"sel_freq = true f, DF = DF1 = {r['df']:.3g} Hz, EFDD DF2 = {r['df2']:.3g} Hz, npmax = {npmax}")
    head = ("mode", "f_true Hz", "ours |e|", "|e|/1σ", "found", "FDD |e|", "EFDD |e|", "best")
    widths = (4, 10, 9, 7, 5, 9, 9, 5)
    print("  " + " ".join(h.rjust(w) for h, w in zip(head, widths)))
    print("  " + " ".join("-" * w for w in widths))
    for k, f in enumerate(truth):
        e = {m: per_mode[m][k] for m in ("ours", "FDD", "EFDD")}
        best = min(e, key=lambda m: e[m]) if min(e.values()) < NONE_WITHIN else "none"
        row = (str(k + 1), f"{f:.4f}", fmt_err(e["ours"]), "-" if np.isnan(z[k]) else f"{z[k]:.2f}",
               f"{found[k]}/{n_rec}", fmt_err(e["FDD"]), fmt_err(e["EFDD"]), best)
        print("  " + " ".join(c.rjust(w) for c, w in zip(row, widths)))
    med = {m: float(np.median(per_mode[m])) for m in per_mode}
    z_all = "-" if np.all(np.isnan(z)) else f"{np.nanmedian(z):.2f}"
    row = ("med", "", fmt_err(med["ours"]), z_all, f"{found.sum()}/{n_rec * truth.size}",
           fmt_err(med["FDD"]), fmt_err(med["EFDD"]), min(med, key=med.get))
    print("  " + " ".join(c.rjust(w) for c, w in zip(row, widths)))
    signed = {m: np.nanmedian(v) if np.any(~np.isnan(v)) else np.nan for m, v in r["signed"].items()}
    print("  signed median (f_est/f_true - 1) over all modes and records: " + ", ".join(
        f"{m} {signed[m]:+.1e}" for m in ("ours", "FDD", "EFDD")))
    lower_modes = int(np.sum(per_mode["ours"] < np.minimum(per_mode["FDD"], per_mode["EFDD"])))
    lower = med["ours"] < min(med["FDD"], med["EFDD"])
    print(f"  ours lower: {'yes' if lower else 'no'} (median {fmt_err(med['ours'])} vs FDD {fmt_err(med['FDD'])}, "
          f"EFDD {fmt_err(med['EFDD'])}; lower than both on {lower_modes}/{truth.size} modes)   "
          f"time/record: ours {r['times']['ours'] / n_rec:.2f} s, pyOMA FDD+EFDD {r['times']['pyOMA'] / n_rec:.2f} s")
    return {"title": f"{s.name} {case.kind}", "lower": lower, "med": med}


def peak_times(record, repeat: int, holder: dict | None = None) -> tuple[list[float], list[float] | None]:
    """Wall times of ``repeat`` find_peaks calls with BLAS's threads as they come, and as many with BLAS limited
    to one thread (None without threadpoolctl); ``holder['result']``: the last call's result."""
    from stcs_ident.spectra.peaks import find_peaks

    holder = {} if holder is None else holder
    default = wall_times(lambda: holder.update(result=find_peaks(record)), repeat)
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return default, None
    with threadpool_limits(limits=1, user_api="blas"):
        return default, wall_times(lambda: find_peaks(record), repeat)


def in_turns(record, repeat: int, rounds: int, baseline: str, holder: dict):
    """This code's and the ``baseline`` Python's find_peaks times on ``record``, ``rounds`` rounds in turns of
    ``repeat`` runs each (a machine's load drifts: both codes see it alike); the baseline's times, its
    package and its peaks (frequency, 1σ) in a dict."""
    import json
    import pickle
    import subprocess
    import tempfile

    from stcs_ident.spectra.peaks import find_peaks

    find_peaks(record)  # warm-up, as the baseline's side does
    default, single, other = [], [], {"default": [], "single": []}
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "record.pickle")
        with open(path, "wb") as stream:
            pickle.dump(record, stream)
        for _ in range(rounds):
            d, s = peak_times(record, repeat, holder)
            default += d
            single = None if s is None else (single or []) + s
            done = subprocess.run([baseline, os.path.abspath(__file__), "--time-peaks", path, "--repeat",
                                   str(repeat)], capture_output=True, text=True, check=True, cwd=tmp)
            answer = json.loads(done.stdout.strip().splitlines()[-1])
            other["default"] += answer["default"]
            other["single"] = None if answer["single"] is None else other["single"] + answer["single"]
            other.update(package=answer["package"], peaks=answer["peaks"])
    return default, single, other


def time_peaks(path: str, repeat: int) -> None:
    """``--time-peaks``: find_peaks on a pickled record by whichever stcs_ident this Python imports (after one
    call to warm up), ``repeat`` runs with BLAS's threads and as many on one; one JSON line."""
    import json
    import pickle

    from stcs_ident.spectra.peaks import find_peaks

    with open(path, "rb") as stream:
        record = pickle.load(stream)
    result = find_peaks(record)
    default, single = peak_times(record, repeat)
    print(json.dumps({"package": os.path.dirname(sys.modules["stcs_ident"].__file__), "default": default,
                      "single": single, "peaks": [(p.frequency, p.uncertainty) for p in result.peaks]}))


def same_peaks(ours, theirs) -> str:
    """How far the two codes' peaks are apart: their counts, and the largest |Δf| / 1σ of the peaks in order."""
    if len(ours) != len(theirs):
        return f"{len(ours)} peaks against the baseline's {len(theirs)}"
    worst = max((abs(p.frequency - f) / u for p, (f, u) in zip(ours, theirs)), default=0.0)
    return f"the same {len(ours)} peaks, frequencies within {worst:.1e} of their 1σ"


def throughput(quick: bool, with_fdd: bool = True, repeat: int | None = None, baseline: str | None = None,
               rounds: int = 2) -> dict:
    """16 sensors x 10 min at 256 Hz, ambient, of the stay: find_peaks and (`with_fdd`) pyOMA FDD wall time;
    with ``baseline`` (another Python) that installation's find_peaks too (:func:`in_turns`)."""
    from stcs_ident.forward import count_below
    from stcs_ident.simulate.simulate import NYQUIST_FRACTION, Ambient

    _, stay = structures()
    fs, duration, n_channels = 256.0, 600.0, 16
    case = Case(stay, "ambient", fs, duration, Ambient(50.0, correlation_length=5.0), (), (7,))
    # irregular spacing over the lower half: no mode has a node at (nearly) every sensor
    positions = np.sort(np.random.default_rng(16).uniform(3.0, 65.0, n_channels)).round(2)
    t = time.perf_counter()
    record = simulate(case, 7, positions=tuple(positions), sampling_rate=fs)
    t_sim = time.perf_counter() - t
    n_true = count_below(stay.cable, list(stay.attachments), stay.tension, NYQUIST_FRACTION * fs)
    truth = true_frequencies(stay, n_true)
    gaps = np.diff(truth)
    spacing = np.minimum(np.r_[np.inf, gaps], np.r_[gaps, np.inf])
    repeat = repeat or (1 if quick else 3)

    holder = {}
    if baseline is None:
        ours_default, ours_single = peak_times(record, repeat, holder)
        other = None
    else:
        ours_default, ours_single, other = in_turns(record, repeat, rounds, baseline, holder)
    found = np.array([p.frequency for p in holder["result"].peaks])
    err = np.full(truth.size, np.nan)
    for k, ft in enumerate(truth):
        j = int(np.argmin(np.abs(found - ft)))
        if abs(found[j] - ft) <= MATCH_FRACTION * spacing[k]:
            err[k] = abs(found[j] / ft - 1)

    nxseg = pyoma_nxseg(fs, record.n_samples, truth[0], stay.damping)
    result = {"shape": record.acceleration.shape, "t_sim": t_sim, "ours": ours_default, "ours_1": ours_single,
              "fdd": None, "nxseg": nxseg, "n_true": n_true, "missed": [k + 1 for k in np.flatnonzero(np.isnan(err))],
              "n_peaks": len(holder["result"].peaks), "err": float(np.nanmedian(err)), "fdd_err": float("nan"),
              "repeat": repeat, "baseline": other,
              "same": None if other is None else same_peaks(holder["result"].peaks, other["peaks"])}
    if not with_fdd:
        return result
    from pyoma2.algorithms.fdd import FDD
    from pyoma2.setup.single import SingleSetup

    def fdd():
        setup = SingleSetup(record.acceleration, fs)
        setup.add_algorithms(FDD(name="FDD", nxseg=nxseg, method_SD="per"))
        with quiet():
            setup.run_all()
            setup.mpe("FDD", sel_freq=list(truth), DF=PYOMA_DF_FRACTION * gaps.min())
        holder["fdd"] = np.asarray(setup["FDD"].result.Fn, dtype=float)

    result["fdd"] = wall_times(fdd, repeat)
    result["fdd_err"] = float(np.median(np.abs(holder["fdd"] / truth - 1)))
    return result


def print_throughput(tp: dict) -> None:
    n, c = tp["shape"]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    runs = len(tp["ours"])
    print(f"\nThroughput: ambient record of the stay, {c} channels x {n / 256.0:g} s at 256 Hz ({n * c:,} samples; "
          f"simulated in {tp['t_sim']:.1f} s); {runs} run{'s' if runs > 1 else ''} each, "
          f"{os.cpu_count()} CPUs, load average {load:.2f}")
    widths = (36, 8, 8, 8, 30)
    head = ("method", "median s", "min s", "target", "modes, median |e|")
    print("  " + " ".join(h.rjust(w) for h, w in zip(head, widths)))
    print("  " + " ".join("-" * w for w in widths))
    n_found = tp["n_true"] - len(tp["missed"])
    rows = [("find_peaks (blind)", tp["ours"], f"<= {THROUGHPUT_TARGET:g}",
             f"{n_found}/{tp['n_true']} found, {fmt_err(tp['err'])}")]
    if tp["ours_1"] is not None:
        rows.append(("find_peaks, BLAS limited to 1 thread", tp["ours_1"], f"<= {THROUGHPUT_TARGET:g}", "same"))
    base = tp.get("baseline")
    if base is not None:
        rows.append(("baseline find_peaks (blind)", base["default"], "", "the code before"))
        if base["single"] is not None:
            rows.append(("baseline, BLAS limited to 1 thread", base["single"], "", "the code before"))
    if tp["fdd"] is not None:
        rows.append((f"pyOMA FDD, nxseg {tp['nxseg']}, at truth", tp["fdd"], "",
                     f"{tp['n_true']} given, {fmt_err(tp['fdd_err'])}"))
    for name, times, target, acc in rows:
        cells = (name, f"{statistics.median(times):.2f}", f"{min(times):.2f}", target, acc)
        print("  " + " ".join(x.rjust(w) for x, w in zip(cells, widths)))
    if base is not None:
        pairs = [("threads as they come", tp["ours"], base["default"])]
        if tp["ours_1"] is not None and base["single"] is not None:
            pairs.append(("BLAS on 1 thread", tp["ours_1"], base["single"]))
        print(f"  baseline: {base['package']}; this code / baseline, median and min: " + "; ".join(
            f"{label} {statistics.median(a) / statistics.median(b):.2f}, {min(a) / min(b):.2f}"
            for label, a, b in pairs))
        print(f"  results: {tp['same']}")
    ok = statistics.median(tp["ours"]) <= THROUGHPUT_TARGET
    print(f"  find_peaks within target (median, default threads): {'yes' if ok else 'NO'}; "
          f"{tp['n_peaks']} peaks reported in 0-{0.45 * 256:g} Hz; modes not reported: "
          f"{', '.join(map(str, tp['missed'])) or 'none'}")
    if load > 0.5 * (os.cpu_count() or 1):
        print("  (other processes were running: wall times are inflated; compare the min column and the 1-thread row)")


def planes_throughput(repeat: int = 5, seeds=(0, 1, 2), baseline: str | None = None) -> dict:
    """Seconds per channel of analyse_record on biaxial records of the stay read per plane and read as one
    plane (minimum over ``repeat`` runs, summed over the seeds' records); with ``baseline`` (another Python,
    with another stcs_ident installed) that code's times on the same records too."""
    import json
    import pickle
    import subprocess
    import tempfile

    try:
        from benchmarks.plane_records import make_case
        from benchmarks.time_records import seconds_per_channel
    except ImportError:  # run as a script from the repository's root
        from plane_records import make_case
        from time_records import seconds_per_channel

    cases = [make_case("stay", seed, layout="biaxial") for seed in seeds]
    records = [(c.campaign, c.test, c.record) for c in cases]
    out = {"this": seconds_per_channel(records, repeat), "n_channels": sum(c.record.n_channels for c in cases),
           "repeat": repeat, "records": len(cases)}
    if baseline is not None:
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "records.pickle")
            with open(path, "wb") as stream:
                pickle.dump(records, stream)
            script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "time_records.py")
            done = subprocess.run([baseline, script, path, "--repeat", str(repeat)], capture_output=True, text=True,
                                  check=True, cwd=tmp)  # not this checkout: the baseline's installed package
        out["baseline"] = json.loads(done.stdout.strip().splitlines()[-1])
    return out


def print_planes_throughput(tp: dict) -> None:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"\nPlanes: analyse_record on {tp['records']} biaxial records of the stay ({tp['n_channels']} channels in "
          f"all), minimum of {tp['repeat']} runs, load average {load:.2f}")
    this = tp["this"]
    for label in ("planes", "one plane"):
        print(f"  this code, read {label:>9}: {1e3 * this[label]:8.1f} ms per channel")
    print(f"  ratio planes / one plane: {this['planes'] / this['one plane']:.2f}")
    if "baseline" in tp:
        base = tp["baseline"]
        path = "compiled kernel" if base["kernel"] else "numpy fallback"
        print(f"  baseline ({base['package']}, {path}), every record read as it reads them: "
              f"{1e3 * base['one plane']:8.1f} ms per channel")
        print(f"  ratio this code per plane / baseline: {this['planes'] / base['one plane']:.2f}; "
              f"one plane / baseline: {this['one plane'] / base['one plane']:.2f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one record per case and one timing repeat (~30 s)")
    parser.add_argument("--throughput", action="store_true",
                        help="only the find_peaks throughput case (no pyOMA-2 needed), --repeat runs")
    parser.add_argument("--planes", action="store_true",
                        help="only the per-channel time of a biaxial record read per plane and as one plane")
    parser.add_argument("--repeat", type=int, default=5, help="timing runs with --throughput (default 5)")
    parser.add_argument("--baseline", metavar="PYTHON",
                        help="with --planes or --throughput: also time the same records with the stcs_ident of "
                             "this Python")
    parser.add_argument("--rounds", type=int, default=2,
                        help="with --throughput --baseline: rounds of --repeat runs of each code, in turns (default 2)")
    parser.add_argument("--time-peaks", metavar="PICKLE", help=argparse.SUPPRESS)  # the baseline's side of it
    args = parser.parse_args(argv)
    if args.time_peaks:
        time_peaks(args.time_peaks, max(1, args.repeat))
        return 0
    if args.planes:
        print_header()
        print_planes_throughput(planes_throughput(max(1, args.repeat), baseline=args.baseline))
        return 0
    print_header()
    if args.throughput:
        print_throughput(throughput(quick=False, with_fdd=False, repeat=max(1, args.repeat), baseline=args.baseline,
                                    rounds=max(1, args.rounds)))
        return 0
    try:
        import pyoma2
    except ImportError:
        print(PYOMA_MISSING)
        return 0
    logging.getLogger("pyoma2").setLevel(logging.WARNING)
    import pyoma2.algorithms.fdd
    import pyoma2.setup.single  # noqa: F401

    import stcs_ident.spectra.peaks  # noqa: F401
    version = getattr(sys.modules["pyoma2"], "__version__", None)
    if version is None:
        from importlib.metadata import PackageNotFoundError
        from importlib.metadata import version as dist_version

        try:
            version = dist_version("pyoma-2")
        except PackageNotFoundError:
            version = "?"

    t0 = time.perf_counter()
    print(f"Modal frequencies: stcs_ident find_peaks vs pyOMA-2 {version} FDD / EFDD, same simulated records")
    print("|e| = |f_est / f_true - 1|, per mode the median over the case's records; 'miss' = not reported.")
    print("NOTE: pyOMA's peaks are picked at the TRUE frequencies (sel_freq = truth) and its nxseg is set from the")
    print("true ζ and f1 -- this favours pyOMA; find_peaks is told nothing (blind detection + fit).")
    summary = [print_case(run_case(c)) for c in cases(args.quick)]

    print_throughput(throughput(args.quick))

    print("\nSummary (acceptance: frequency error per mode for both, ours lower) -- median |e| over modes")
    print("  " + " ".join(h.rjust(w) for h, w in zip(("case", "ours", "FDD", "EFDD", "ours lower"), (16, 9, 9, 9, 10))))
    for s in summary:
        cells = (s["title"], fmt_err(s["med"]["ours"]), fmt_err(s["med"]["FDD"]), fmt_err(s["med"]["EFDD"]),
                 "yes" if s["lower"] else "no")
        print("  " + " ".join(c.rjust(w) for c, w in zip(cells, (16, 9, 9, 9, 10))))
    print(f"\ntotal run time {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
