"""Time of the simulator's biaxial-plus-axial records: the calibration and acceptance sets need hundreds.

200 records (``--records N``) of 10 minutes at 50 Hz of a 200 m stay (both planes, 57 modes each), three
channels (in, out, axial) at one position, a deck mode moving an anchorage and traffic, written to nothing:
the seconds per record of ``simulate_record``, with BLAS limited to one thread when threadpoolctl is
importable (a multi-threaded BLAS on a loaded machine spends up to 7x the time on the many tiny matrices of
the modal superposition). Measured (2 cores, one BLAS thread): 0.20-0.25 s a record.

    python benchmarks/simulate_planes.py [--records N]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import time

from common import print_header

import stcs_ident as si
from stcs_ident.simulate import Ambient, simulate_record
from stcs_ident.simulate.bridge import BridgeConditions, StructuralMode, Traffic

STAY = si.Cable(length=200.0, mass_per_length=80.0, EI=2e4, EA=2e9, inclination=math.radians(25))
TENSION = 2.0e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=200)
    args = parser.parse_args()
    print_header()
    try:
        from threadpoolctl import threadpool_limits
        limit, blas = threadpool_limits(limits=1, user_api="blas"), "one BLAS thread"
    except ImportError:
        limit, blas = contextlib.nullcontext(), "BLAS threads as they come (threadpoolctl not installed)"
    bridge = BridgeConditions(anchorage_motion=[StructuralMode(0.65, 0.02, direction=(0.8, 0.3, 0.5))],
                              traffic=Traffic(30.0))
    with limit:
        start = time.perf_counter()
        for seed in range(args.records):
            simulate_record(STAY, [], TENSION, [61.0, 61.0, 61.0], directions=["in", "out", "axial"],
                            duration=600.0, sampling_rate=50.0, ambient=Ambient(2.0), snr_db=40.0, seed=seed,
                            bridge=bridge)
            if (seed + 1) % 50 == 0:
                print(f"  {seed + 1} of {args.records} records", flush=True)
        elapsed = time.perf_counter() - start
    print(f"{args.records} records of 10 min at 50 Hz, in/out/axial, a deck mode and traffic ({blas}): "
          f"{elapsed:.1f} s, {elapsed / args.records:.3f} s a record")


if __name__ == "__main__":
    main()
