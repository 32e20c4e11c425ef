"""Identification benchmark: the contour method's parameter sweep, exact DSM against finite elements.

The paper's contour method needs every measured mode at every point of a
(tension, EI) grid. For han2020 case 1 level 4 (bare strand, 6 modes):

1. the default 201 × 201 grid × 6 modes through the identification code
   path (``Problem.predict``, one vectorised call of the exact DSM batch
   solver); target ≤ 3 s;
2. the same sweep by the finite-element model (``fe_frequencies``, ARPACK
   shift-invert on a banded factorisation) on a coarse grid, with the
   coarsest uniform mesh whose mode 6 is within 1e-6 of the exact value at
   the nominal point; its time per grid point gives the ratio and the time
   the full grid would take;
3. for scale: the whole contour identification and the least-squares fit.

With ``--figures DIR`` it also writes the identification figures of
han2020: case 1 level 4 (tension, EI) after the paper's Figs. 23-24, and
the weight positions of cases 2 and 3 (after its Fig. 25) with tension and
EI first corrected by a joint least-squares fit of all six tests.

Run: ``python benchmarks/identify.py [--quick] [--figures DIR]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import CHECKOUT, print_header, timed

from stcs_ident.forward import natural_frequencies
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.identify import Problem, fit_contour, fit_lsq, gather_measurements, parse_parameters
from stcs_ident.io.campaign import load_campaign

ROOT = CHECKOUT  # campaigns/ of this checkout
TARGET_ACCURACY = 1e-6  # relative, on mode 6 at the nominal point
TEST = "case1-L4"


def fe_mesh_for(cable, tension, exact6):
    """Coarsest uniform mesh whose mode 6 is within TARGET_ACCURACY of the exact value."""
    for n in range(20, 2001, 4):
        f = fe_frequencies(cable, [], tension, 6, n_elements=n, solver="sparse")
        if abs(f[5] / exact6 - 1) <= TARGET_ACCURACY:
            return n, abs(f[5] / exact6 - 1)
    raise RuntimeError("no FE mesh reached the target accuracy")


def write_figures(directory: Path) -> None:
    """han2020 figures: case1-L4 (tension, EI) and the weight positions of cases 2 and 3."""
    from stcs_ident.identify import identify
    from stcs_ident.identify.corrected import corrected_campaign
    from stcs_ident.report.identify_figures import save_identify_figures

    campaign = load_campaign(ROOT / "campaigns" / "han2020")
    lsq = identify(campaign, [TEST], "tension,EI")
    contour = identify(campaign, [TEST], "tension,EI", method="contour")
    for path in save_identify_figures(contour, directory / TEST, lsq=lsq):
        print(f"wrote {path}")
    loaded = ["case2-L4", "case2-L5", "case3-L4", "case3-L5"]
    everything = identify(campaign, ["case1-L4", "case1-L5", *loaded], "tension,EI,position")
    fixed = corrected_campaign(campaign, everything)
    lsq = identify(fixed, loaded, "position")
    contour = identify(fixed, loaded, "position", method="contour")
    for path in save_identify_figures(contour, directory / "case2-case3-positions", lsq=lsq):
        print(f"wrote {path}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats and a smaller FE grid")
    parser.add_argument("--figures", metavar="DIR", help="also write the han2020 identification figures into DIR")
    args = parser.parse_args(argv)
    print_header()
    if args.figures:
        write_figures(Path(args.figures))
    campaign = load_campaign(ROOT / "campaigns" / "han2020")
    measurements, _ = gather_measurements(campaign, [TEST])
    params = parse_parameters(campaign, [m.test for m in measurements], "tension,EI")
    problem = Problem(campaign, measurements, params)
    n_side = 201
    r1 = np.linspace(0.9, 1.1, n_side)
    r2 = np.linspace(0.5, 1.5, n_side)
    a, b = np.meshgrid(r1, r2, indexing="ij")
    X = np.stack([a.ravel(), b.ravel()], axis=1)

    t_dsm, F = timed(lambda: problem.predict(X), 1 if args.quick else 3)

    cable = campaign.cable
    test = campaign.test(TEST)
    exact6 = natural_frequencies(cable, [], test.tension, 6)[5]
    n_el, err = fe_mesh_for(cable, test.tension, exact6)
    n_fe = 5 if args.quick else 11
    idx1 = np.linspace(0, n_side - 1, n_fe).round().astype(int)
    idx2 = np.linspace(0, n_side - 1, n_fe).round().astype(int)
    worst = 0.0
    t = time.perf_counter()
    for i in idx1:
        for j in idx2:
            fe = fe_frequencies(replace(cable, EI=cable.EI * r2[j]), [], test.tension * r1[i], 6,
                                n_elements=n_el, solver="sparse")
            worst = max(worst, float(np.abs(fe / F[i * n_side + j] - 1).max()))
    t_fe_per = (time.perf_counter() - t) / (n_fe * n_fe)
    t_dsm_per = t_dsm / len(X)

    t_contour, _ = timed(lambda: fit_contour(problem), 1)
    t_lsq, _ = timed(lambda: fit_lsq(problem), 1 if args.quick else 5)

    print(f"\nIdentification sweep, han2020 {TEST}: {n_side} x {n_side} (tension, EI) grid x 6 modes")
    print(f"FE mesh: {n_el} elements (mode-6 error {err:.1e} at the nominal point); FE timed on a "
          f"{n_fe} x {n_fe} sub-grid; largest FE-DSM difference there, modes 1-6: {worst:.1e}")
    rows = [
        (f"sweep {n_side}x{n_side}x6 (total)", f"{t_dsm:.2f} s", f"{t_fe_per * len(X):.0f} s (est.)", "",
         "<= 3 s"),
        ("per grid point", f"{t_dsm_per * 1e6:.1f} us", f"{t_fe_per * 1e3:.2f} ms", f"{t_fe_per / t_dsm_per:.0f}x",
         ""),
        ("contour identification (whole)", f"{t_contour:.2f} s", "", "", ""),
        ("lsq identification", f"{t_lsq * 1e3:.0f} ms", "", "", ""),
    ]
    widths = [32, 10, 16, 7, 8]
    head = ("case", "DSM", "FE", "ratio", "target")
    print(" | ".join(h.ljust(w) for h, w in zip(head, widths)))
    print("-+-".join("-" * w for w in widths))
    for row in rows:
        print(" | ".join(str(c).ljust(w) for c, w in zip(row, widths)))
    return 0 if t_dsm <= 3.0 else 1


if __name__ == "__main__":
    sys.exit(main())
