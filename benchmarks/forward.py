"""Forward solver benchmark: the exact DSM against a finite-element model of
equal accuracy, side by side in one run.

1. One call: the first 10 frequencies of a 4-attachment cable.
2. A batch: 40,000 parameter sets (200 tensions × 200 EI values) × 6 modes
   of the han2020 case 2 cable (one 8.3 kg weight at midspan).

The FE baseline is ``stcs_ident.forward.fem`` solved with ARPACK in
shift-invert mode on a banded Cholesky factorisation (scipy's sparse
symmetric eigensolver, no dense solve), with the coarsest uniform mesh that
reaches 1e-6 relative on mode 10 against the exact solver. The FE batch is
timed on a random sample of the grid and reported per configuration.

Run: ``python benchmarks/forward.py [--quick]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np
from common import CHECKOUT, print_header, timed

from stcs_ident.core.model import Attachment, Cable
from stcs_ident.forward import batch_frequencies, natural_frequencies
from stcs_ident.forward.fem import fe_frequencies
from stcs_ident.io.campaign import load_campaign

ROOT = CHECKOUT  # campaigns/ of this checkout
TARGET_ACCURACY = 1e-6  # relative, on mode 10


def fe_mesh_for(cable, atts, tension, exact10):
    """Coarsest uniform mesh whose mode 10 is within TARGET_ACCURACY."""
    for n in range(40, 2001, 4):
        f = fe_frequencies(cable, atts, tension, 10, n_elements=n, solver="sparse")
        if abs(f[9] / exact10 - 1) <= TARGET_ACCURACY:
            return n, abs(f[9] / exact10 - 1)
    raise RuntimeError("no FE mesh reached the target accuracy")


def one_call(repeat):
    cable = Cable(length=60.0, mass_per_length=25.0, EI=2.0e5, EA=1.2e9, inclination=math.radians(25))
    atts = [Attachment("damper", 3.0, 40.0, 2.0e5), Attachment("clamp1", 17.5, 12.0),
            Attachment("clamp2", 31.0, 12.0), Attachment("sensor", 44.2, 3.0)]
    tension = 3.0e6
    exact = natural_frequencies(cable, atts, tension, 10)
    n, err = fe_mesh_for(cable, atts, tension, exact[9])
    t_dsm, _ = timed(lambda: natural_frequencies(cable, atts, tension, 10), repeat)
    t_fe, _ = timed(lambda: fe_frequencies(cable, atts, tension, 10, n_elements=n, solver="sparse"), repeat)
    return {"dsm": t_dsm, "fe": t_fe, "fe_elements": n, "fe_error": err}


def batch(quick):
    campaign = load_campaign(ROOT / "campaigns" / "han2020")
    cable = campaign.cable
    atts = campaign.setup("case2").attachments
    nominal = campaign.test("case2-L4").tension
    n_side = 60 if quick else 200
    tension = nominal * np.linspace(0.8, 1.2, n_side)
    EI = cable.EI * np.linspace(0.5, 1.5, n_side)
    exact10 = natural_frequencies(cable, atts, nominal, 10)[9]
    n_el, err = fe_mesh_for(cable, atts, nominal, exact10)

    done = [0]

    def progress(k, total):
        if k >= done[0] + total // 5 or k == total:
            done[0] = k
            print(f"  batch: {k}/{total} parameter sets", file=sys.stderr)

    t = time.perf_counter()
    F = batch_frequencies(cable, atts, tension[:, None], 6, EI=EI[None, :], progress=progress)
    t_dsm = time.perf_counter() - t

    rng = np.random.default_rng(0)
    sample = rng.integers(0, n_side, (40 if quick else 100, 2))
    from dataclasses import replace

    t = time.perf_counter()
    worst = 0.0
    for i, j in sample:
        fe = fe_frequencies(replace(cable, EI=EI[j]), atts, tension[i], 6, n_elements=n_el, solver="sparse")
        worst = max(worst, float(np.abs(fe / F[i, j] - 1).max()))
    t_fe = (time.perf_counter() - t) / len(sample)
    return {"n": F.shape[0] * F.shape[1], "dsm_total": t_dsm, "dsm_per": t_dsm / (F.shape[0] * F.shape[1]),
            "fe_per": t_fe, "fe_elements": n_el, "fe_error": err, "fe_vs_dsm": worst}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a smaller batch (3,600 sets)")
    args = parser.parse_args(argv)
    print_header()
    one = one_call(repeat=30 if args.quick else 100)
    b = batch(args.quick)
    rows = [
        ("one call, 10 modes, 4 attachments", f"{one['dsm'] * 1e3:.2f} ms", f"{one['fe'] * 1e3:.2f} ms",
         f"{one['fe'] / one['dsm']:.1f}x", "<= 5 ms, >= 10x"),
        (f"batch {b['n']:,} sets x 6 modes (total)", f"{b['dsm_total']:.2f} s",
         f"{b['fe_per'] * b['n']:.0f} s (est.)", "", "<= 5 s" if not args.quick else "(quick)"),
        ("batch, per configuration", f"{b['dsm_per'] * 1e6:.1f} us", f"{b['fe_per'] * 1e3:.2f} ms",
         f"{b['fe_per'] / b['dsm_per']:.0f}x", ">= 100x"),
    ]
    print("\nForward solver: exact DSM vs finite elements (ARPACK shift-invert, banded Cholesky)")
    print(f"FE meshes: {one['fe_elements']} elements (one call, mode-10 error {one['fe_error']:.1e}); "
          f"{b['fe_elements']} elements (batch, mode-10 error {b['fe_error']:.1e}); "
          f"largest FE-DSM difference in the batch sample, modes 1-6: {b['fe_vs_dsm']:.1e}")
    widths = [38, 12, 16, 8, 16]
    head = ("case", "DSM", "FE", "ratio", "target")
    print(" | ".join(h.ljust(w) for h, w in zip(head, widths)))
    print("-+-".join("-" * w for w in widths))
    for row in rows:
        print(" | ".join(str(c).ljust(w) for c, w in zip(row, widths)))


if __name__ == "__main__":
    main()
