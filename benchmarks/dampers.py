"""Dampers (issue 13): the complex solver's cost, the tension bias of ignoring a damper, and the
identification of tension and dashpot from simulated field records of a 200 m stay.

1. Forward: 10 complex modes of a 200 m stay with one damper (certified count) against the undamped call
   of the same cable (the damper's spring and mass kept), side by side; target <= 5x.
2. Bias: stays of 100-250 m, a damper at 2 % of the length, η₁ = c π x_d/(l √(H m)) from 0 to 10. The
   exact model's frequencies of modes 1-10 are "measured" (σ 1e-4 f); tension (and EI) identified with the
   damper ignored: the DSM without it, and the taut-string hand formula from mode 1. With the damper in
   the model the fit returns the true tension (checked).
3. Identification: `stcs-ident simulate` records of a 200 m stay with a damper (ambient wind plus hand
   blows, 30 min at 50 Hz, SNR 20 dB, own damping 0.2 %, tension 2 % above the stated one, coefficient
   20 % below the recorded one), then `spectra` and `identify --params tension,EI,coefficient`: errors of
   tension and coefficient against the truth, with their 1σ; and the tension with the damper ignored.

``--report DIR`` also writes the figures (universal curve, complex mode shapes, tension bias), the bias
table as CSV and a report.md. Run: ``python benchmarks/dampers.py [--quick] [--report reports/dampers]``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np
import tomli_w
from common import print_header, timed

from stcs_ident.core.model import Attachment, Cable, Campaign, Damper, Setup, Test
from stcs_ident.forward import damped, natural_frequencies
from stcs_ident.forward.damped import complex_modes
from stcs_ident.forward.damped_shapes import complex_mode_shapes
from stcs_ident.identify import identify
from stcs_ident.identify.problem import Measurement

STAY = Cable(200.0, 80.0, 5.0e5, EA=2.0e9, inclination=math.radians(30.0))
H = 5.0e6
XD = 4.0  # m, 2 % of the length
DURATION = 1800  # s: a 30-minute record (the damping ratios of the low modes carry the dashpot)


def optimum(cable: Cable, tension: float, xd: float) -> float:
    """The dashpot that makes η₁ = 1 (N s/m)."""
    return math.sqrt(tension * cable.mass_per_length) * cable.length / (math.pi * xd)


def forward_cost(repeat: int) -> dict:
    damper = [Damper("D1", XD, 10.0, coefficient=optimum(STAY, H, XD))]
    plain = [Attachment("D1", XD, 10.0)]
    t_damped, _ = timed(lambda: complex_modes(STAY, damper, H, 10), repeat)
    t_free, _ = timed(lambda: complex_modes(STAY, damper, H, 10, certify=False), repeat)
    t_undamped, _ = timed(lambda: natural_frequencies(STAY, plain, H, 10), repeat)
    return {"damped": t_damped, "uncertified": t_free, "undamped": t_undamped}


STAYS = {  # length: (mass per length kg/m, tension N, EI N m²)
    100.0: (50.0, 2.5e6, 1.5e5),
    150.0: (65.0, 4.0e6, 3.0e5),
    200.0: (80.0, 5.0e6, 5.0e5),
    250.0: (95.0, 6.5e6, 8.0e5),
}
ETAS = np.array([0.0, 0.1, 0.3, 0.5, 1.0, 2.0, 3.0, 5.0, 10.0])


def bias_table(etas=ETAS) -> list[dict]:
    """Tension bias of the models that ignore the damper, per stay and η₁ (see the module docstring)."""
    rows = []
    modes = np.arange(1, 11)
    for length, (m, tension, EI) in STAYS.items():
        cable = Cable(length, m, EI, EA=2.0e11 * m / 7850.0, inclination=math.radians(30.0))
        xd = 0.02 * length
        for eta in etas:
            atts = [Damper("D1", xd, 10.0, coefficient=eta * optimum(cable, tension, xd))] if eta > 0 else \
                [Attachment("D1", xd, 10.0)]
            truth = complex_modes(cable, atts, tension, 10) if eta > 0 else None
            f = truth.frequency if truth is not None else natural_frequencies(cable, atts, tension, 10)
            # the CSV's columns carry their units (docs/formats.md): η₁ = c / c_opt,1 and ζ₁ are ratios
            row = {"length_m": length, "eta1_ratio": float(eta), "mode1_damping_ratio": 0.0 if truth is None else
                   float(truth.damping[0])}
            plain = Campaign("bias", cable, (Setup("S", (Attachment("D1", xd, 10.0),)),),
                             (Test("T", "S", tension),))
            meas = {"T": Measurement(plain.tests[0], modes, f, 1e-4 * f, "given")}
            for label, params in (("dsm_tension_EI", "tension,EI"), ("dsm_tension", "tension")):
                r = identify(plain, params=params, picked=meas)
                row[f"{label}_error_percent"] = 100 * (r.value("tension")[0] / tension - 1)
            row["string_mode1_error_percent"] = 100 * (4 * m * length**2 * f[0] ** 2 / tension - 1)
            if truth is not None:  # the model with the damper returns the truth
                with_damper = Campaign("bias", cable, (Setup("S", tuple(atts)),), (Test("T", "S", tension),))
                meas = {"T": Measurement(with_damper.tests[0], modes, f, 1e-4 * f, "given")}
                r = identify(with_damper, params="tension,EI", picked=meas)
                row["with_damper_error_percent"] = 100 * (r.value("tension")[0] / tension - 1)
            else:
                row["with_damper_error_percent"] = row["dsm_tension_EI_error_percent"]
            rows.append(row)
    return rows


CAMPAIGN = """\
[campaign]
name = "stay200"
description = "A 200 m stay with a viscous damper 4 m from the deck anchorage"

[cable]
length = 200.0
mass_per_length = 80.0
EI = 5.0e5
EA = 2.0e9
inclination = 30.0
boundary = "clamped"

[[setup]]
name = "damped"
  [[setup.damper]]
  name = "D1"
  position = 4.0
  coefficient = {recorded}
  mass = 10.0

[[test]]
name = "t1"
setup = "damped"
tension = 5.0e6
"""


def run(*args) -> str:
    out = subprocess.run([str(Path(sys.executable).parent / "stcs-ident"), *map(str, args)], capture_output=True,
                         text=True, check=False)
    if out.returncode:
        raise RuntimeError(f"stcs-ident {' '.join(map(str, args))}: {out.stderr.strip()}")
    return out.stdout


def identification(seeds, work: Path) -> list[dict]:
    """End-to-end identification on simulated records (see the module docstring)."""
    c_true = optimum(STAY, 1.02 * H, XD)
    recorded = 1.25 * c_true
    rows = []
    for seed in seeds:
        case = work / f"seed{seed}"
        case.mkdir()
        (case / "campaign.toml").write_text(CAMPAIGN.format(recorded=f"{recorded:.6g}"))
        run("simulate", case, "--out", case / "sim", "--duration", DURATION, "--sampling-rate", 50, "--ambient", 20,
            "--impulses", 4, "--snr", 20, "--damping", 0.002, "--tension-ratio", 1.02, "--damper-coefficient",
            f"D1@{c_true:.6g}", "--seed", seed, "--sensors", "0.06,0.37,0.71")
        t = time.perf_counter()
        run("identify", case / "sim", "--params", "tension,EI,coefficient", "--json", case / "id.json")
        elapsed = time.perf_counter() - t
        result = json.loads((case / "id.json").read_text())
        values, sigma = result["values"], result["value_uncertainty"]
        tension = values["tension"]["t1"]
        coefficient = values["coefficient"]["D1"]
        # the damper ignored: the same picked frequencies, a campaign without it
        plain = case / "plain"
        plain.mkdir()
        # The campaign as simulate wrote it, its dampers left out (read and written as TOML, not cut as text:
        # the writer's layout is tomli-w's to choose).
        data = tomllib.loads((case / "sim" / "campaign.toml").read_text())
        for setup in data.get("setup", []):
            setup.pop("damper", None)
        (plain / "campaign.toml").write_text(tomli_w.dumps(data))
        (plain / "records").symlink_to((case / "sim" / "records").resolve())
        run("identify", plain, "--params", "tension,EI", "--json", case / "id_plain.json")
        ignored = json.loads((case / "id_plain.json").read_text())["values"]["tension"]["t1"]
        rows.append({"seed": seed, "seconds": elapsed,
                     "tension_%": 100 * (tension / (1.02 * H) - 1),
                     "tension_sigma_%": 100 * sigma["tension"]["t1"] / (1.02 * H),
                     # the frequencies' share of that σ (the rest: the tolerances of the values held fixed)
                     "tension_sigma_frequencies_%": 100 * result["uncertainty_sources"]["frequencies"]
                     ["tension_ratio"]["t1"] / 1.02,
                     "coefficient_%": 100 * (coefficient / c_true - 1),
                     "coefficient_sigma_%": 100 * sigma["coefficient"]["D1"] / c_true,
                     "ignored_tension_%": 100 * (ignored / (1.02 * H) - 1)})
        print(f"  seed {seed}: tension {rows[-1]['tension_%']:+.3f} % (1σ {rows[-1]['tension_sigma_%']:.3f}), "
              f"coefficient {rows[-1]['coefficient_%']:+.1f} % (1σ {rows[-1]['coefficient_sigma_%']:.1f}), "
              f"damper ignored: tension {rows[-1]['ignored_tension_%']:+.2f} %  ({elapsed:.0f} s)",
              file=sys.stderr)
    return rows


def universal_series():
    """ζ_n/(x_d/l) against η_n: a taut string (x_d/l = 0.02) and the 200 m stay with EI and sag."""
    out = {}
    string = Cable(200.0, 80.0, 0.0)
    for label, cable in (("exact, taut string, x_d/l = 0.02", string),
                         ("exact, 200 m stay with EI and sag", STAY)):
        eta, zeta = [], []
        for e1 in np.logspace(-1.5, 1.0, 12):
            modes = complex_modes(cable, [Damper("D1", XD, coefficient=e1 * optimum(cable, H, XD))], H, 4)
            eta += list(e1 * np.arange(1, 5))
            zeta += list(modes.damping / (XD / cable.length))
        out[label] = (np.array(eta), np.array(zeta))
    return out


def write_report(directory: Path, bias_rows, ident_rows, forward) -> None:
    from stcs_ident.core.files import atomic_file, write_figure
    from stcs_ident.report.damped_figures import plot_complex_shapes, plot_tension_bias, plot_universal_curve

    directory.mkdir(parents=True, exist_ok=True)
    write_figure(plot_universal_curve(universal_series())["figure"], directory / "universal_curve.png")
    shapes = complex_mode_shapes(STAY, [Damper("D1", XD, 10.0, coefficient=optimum(STAY, H, XD))], H, 4)
    write_figure(plot_complex_shapes(shapes, STAY.length, [XD])["figure"], directory / "complex_shapes.png")
    eta = np.array([r["eta1_ratio"] for r in bias_rows if r["length_m"] == 200.0])
    curves = {}
    for length in STAYS:
        sel = [r for r in bias_rows if r["length_m"] == length]
        curves[f"{length:.0f} m, DSM fit of H and EI"] = np.array([r["dsm_tension_EI_error_percent"] for r in sel])
    sel = [r for r in bias_rows if r["length_m"] == 200.0]
    curves["200 m, string formula, mode 1"] = np.array([r["string_mode1_error_percent"] for r in sel])
    write_figure(plot_tension_bias(eta, curves)["figure"], directory / "tension_bias.png")
    with atomic_file(directory / "tension_bias.csv") as f:
        writer = csv.DictWriter(f, fieldnames=list(bias_rows[0]))
        writer.writeheader()
        writer.writerows(bias_rows)
    lines = ["# Cables with dampers", "",
             ("Generated by `benchmarks/dampers.py --report`. A 200 m stay (80 kg/m, 5 MN, EI 0.5 MN m², sag "
              "included) with a viscous damper 4 m from the anchorage unless said otherwise."), "",
             "## The exact complex modes on Krenk's universal curve", "",
             "![universal curve](universal_curve.png)", "",
             "## Complex mode shapes (damper at mode 1's optimum)", "",
             "![complex mode shapes](complex_shapes.png)", "",
             "## Tension bias when the damper is ignored", "",
             "Damper at 2 % of the length; modes 1-10 fitted with a model without it.", "",
             "![tension bias](tension_bias.png)", "",
             "| length (m) | η₁ | ζ₁ (%) | DSM, H and EI (%) | DSM, H only (%) | string, mode 1 (%) | with damper (%) |",
             "|---|---|---|---|---|---|---|"]
    for r in bias_rows:
        lines.append(f"| {r['length_m']:.0f} | {r['eta1_ratio']:g} | {100 * r['mode1_damping_ratio']:.2f} | "
                     f"{r['dsm_tension_EI_error_percent']:+.2f} | {r['dsm_tension_error_percent']:+.2f} | "
                     f"{r['string_mode1_error_percent']:+.2f} | {r['with_damper_error_percent']:+.3f} |")
    if ident_rows:
        lines += ["", "## Identification from simulated records (SNR 20 dB, 30 min)", "",
                  ("The tension's 1σ holds the tolerances of the values held fixed (the campaign's mass per length "
                   "and length, 1 % and 0.2 % by default: about 1 % of the tension); the simulated stay has its "
                   "nominal mass and length, so its errors stay far inside it. The frequencies' own share of the "
                   "1σ is the next column."), "",
                  ("| seed | tension error (%) | 1σ (%) | of it from the frequencies (%) | coefficient error (%) "
                   "| 1σ (%) | damper ignored (%) |"),
                  "|---|---|---|---|---|---|---|"]
        for r in ident_rows:
            lines.append(f"| {r['seed']} | {r['tension_%']:+.3f} | {r['tension_sigma_%']:.3f} | "
                         f"{r['tension_sigma_frequencies_%']:.3f} | "
                         f"{r['coefficient_%']:+.1f} | {r['coefficient_sigma_%']:.1f} | "
                         f"{r['ignored_tension_%']:+.2f} |")
    ratio = forward["damped"] / forward["undamped"]
    lines += ["", (f"Forward cost, 10 modes with one damper: {forward['damped'] * 1e3:.2f} ms certified, "
                   f"{forward['undamped'] * 1e3:.2f} ms without the dashpot ({ratio:.1f}x)."), ""]
    with atomic_file(directory / "report.md") as f:
        f.write("\n".join(lines))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one simulated record instead of five")
    parser.add_argument("--report", type=Path, help="write figures, the bias table and report.md here")
    args = parser.parse_args(argv)
    print_header()
    print(f"complex-mode solver: {'compiled kernel' if damped.use_kernel() else 'numpy (no compiled kernel)'}")
    forward = forward_cost(repeat=100 if args.quick else 300)
    print("\n1. Forward, 10 modes of a 200 m stay, one damper at 4 m (median of repeated calls)")
    print(f"   complex, certified count: {forward['damped'] * 1e3:.3f} ms; without the count "
          f"{forward['uncertified'] * 1e3:.3f} ms; undamped call {forward['undamped'] * 1e3:.3f} ms")
    print(f"   ratio certified / undamped: {forward['damped'] / forward['undamped']:.2f}x  (target <= 5x)")
    print("\n2. Tension bias with the damper ignored (damper at 2 % of the length, modes 1-10)", file=sys.stderr)
    rows = bias_table()
    print(f"{'l (m)':>6} {'eta1':>6} {'zeta1%':>7} {'DSM H,EI %':>11} {'DSM H %':>8} {'string %':>9} "
          f"{'with damper %':>14}")
    for r in rows:
        print(f"{r['length_m']:6.0f} {r['eta1_ratio']:6g} {100 * r['mode1_damping_ratio']:7.2f} "
              f"{r['dsm_tension_EI_error_percent']:+11.2f} {r['dsm_tension_error_percent']:+8.2f} "
              f"{r['string_mode1_error_percent']:+9.2f} {r['with_damper_error_percent']:+14.4f}")
    print("\n3. Identification from simulated records of the 200 m stay", file=sys.stderr)
    with tempfile.TemporaryDirectory() as tmp:
        ident = identification([1] if args.quick else [1, 2, 3, 4, 5], Path(tmp))
    t = np.array([r["tension_%"] for r in ident])
    c = np.array([r["coefficient_%"] for r in ident])
    print(f"   tension error: max |{np.abs(t).max():.3f}| % (target 0.5 %); coefficient error: max "
          f"|{np.abs(c).max():.1f}| % (target 10 %); damper ignored: tension "
          f"{np.mean([r['ignored_tension_%'] for r in ident]):+.2f} % on average")
    if args.report:
        write_report(args.report, rows, ident, forward)
        print(f"wrote {args.report}")


if __name__ == "__main__":
    main()
