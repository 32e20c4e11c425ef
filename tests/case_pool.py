"""Independent cases of one test on the CPUs this process may use, results in the cases' order.

The statistical tests loop over seeded records (simulate, pick, score) that
do not depend on each other; run one after the other, the second core of a
2-core CI machine sits idle. :func:`map_cases` runs ``fn(case)`` in forked
worker processes (as benchmarks/calibrate_spectra.py runs its records on two
processes): each case is the same function on the same arguments in a copy
of this process, so it gives the same result, and the test checks the same
numbers. A worker inherits
this process's warning filters (pytest's ``error``), so a warning fails the
test as it would here; an exception in a case fails the test with its
traceback. With one CPU (or no fork) the cases run here, in turn.

``fn`` must be a module-level function (it is pickled by name) returning
plain data (numbers, strings, lists, arrays).
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor


def available_cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def map_cases(fn: Callable, cases: Iterable, workers: int | None = None) -> list:
    """``[fn(c) for c in cases]``, on ``workers`` processes (default: the CPUs available)."""
    cases = list(cases)
    workers = min(available_cpus() if workers is None else workers, len(cases))
    if workers <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return [fn(c) for c in cases]
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork")) as pool:
        return list(pool.map(fn, cases))
