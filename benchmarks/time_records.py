"""Seconds per channel of ``analyse_record`` on pickled records, by whichever stcs_ident this Python imports.

``benchmarks/spectra.py --planes --baseline PYTHON`` writes the records (made by this checkout's simulator)
and runs this script under PYTHON, an interpreter with another installed stcs_ident (the code before the
planes, say), so both codes time the same records in one run. It prints one JSON line: the package's
location, the forward solver's code path, and the minimum over the runs of the seconds per channel, with the
records read per plane (their channel directions) and read as one plane (without them; a code before the
planes reads every record so).

    python benchmarks/time_records.py RECORDS.pickle [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import pickle
import time
import warnings


def seconds_per_channel(cases, repeat: int) -> dict:
    from dataclasses import fields, replace

    from stcs_ident.spectra.pipeline import analyse_record

    n_channels = sum(record.acceleration.shape[1] for _, _, record in cases)
    best = {"planes": float("inf"), "one plane": float("inf")}
    for _ in range(repeat):
        for label in ("planes", "one plane"):
            total = 0.0
            for campaign, test, record in cases:
                if label == "one plane" and "channel_directions" in {f.name for f in fields(record)}:
                    record = replace(record, channel_directions=None)
                record = replace(record, acceleration=record.acceleration.copy())  # analysed in place
                start = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    analyse_record(campaign, test, record, "bench")
                total += time.perf_counter() - start
            best[label] = min(best[label], total / n_channels)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("records")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    import stcs_ident
    from stcs_ident.forward import roots

    with open(args.records, "rb") as stream:
        cases = pickle.load(stream)
    times = seconds_per_channel(cases, max(1, args.repeat))
    print(json.dumps({"package": stcs_ident.__file__, "kernel": bool(roots.use_kernel()), **times}))


if __name__ == "__main__":
    main()
