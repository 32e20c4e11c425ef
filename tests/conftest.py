"""Fixtures shared by the test files.

Simulated campaigns are made once per test run (once per pytest-xdist worker) in a session directory of
``tmp_path_factory``, not once per test: a test that reads them must not change them.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import pytest

from stcs_ident.core.model import Campaign
from stcs_ident.simulate.effects import Effects
from tests.diagnose_cases import simulated

BenchRecords = Callable[..., tuple[Campaign, dict]]


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config) -> int | None:
    """``-n auto``: the CPUs this process may use, as the diagnosis counts them (os.sched_getaffinity).

    pytest-xdist's own count (psutil's physical cores when psutil is installed, as dask installs it)
    ignores the affinity a CI runner or ``taskset`` gives and counts two hyperthreads as one core.
    PYTEST_XDIST_AUTO_NUM_WORKERS, when set, is left to pytest-xdist.
    """
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config, items) -> None:
    """``--dist loadgroup`` on a pytest that keeps node ids structured (9.2): the group suffix put where it counts.

    pytest-xdist (3.8) tells the controller a test's ``xdist_group`` by appending ``@group`` to its node id on
    the worker, through the legacy ``_nodeid`` field; pytest 9.2 reads a node's id from ``_id``, so the suffix
    was silently lost and every grouped test distributed alone (pytest-dev/pytest-xdist#1386, open): a module
    fixture meant to be made once under ``-n`` was made on every worker (the planes' acceptance set, 170 s of the
    suite's CPU, twice). Where xdist's suffix is missing it is set here, on the structured id; where xdist sets
    it (older pytest, a fixed xdist) nothing is done.
    """
    if not getattr(config.option, "loadgroup", False):  # not a worker of --dist loadgroup (or no xdist)
        return
    from _pytest.nodeid import coerce_node_id  # the structured id's parser (pytest >= 9.2)

    for item in items:
        names = sorted({str(m.args[0] if m.args else m.kwargs.get("name", "default"))
                        for m in item.iter_markers("xdist_group")})
        suffix = "@" + "_".join(names)
        if names and not item.nodeid.endswith(suffix) and hasattr(item, "_id"):
            item._id = coerce_node_id(item.nodeid + suffix)


@pytest.fixture(scope="session")
def bench_records(tmp_path_factory) -> BenchRecords:
    """``bench_records(bench, effects, seed=0, nominal=None)``: (campaign, spectra by test) of
    tests/diagnose_cases.py's :func:`simulated`, simulated and picked once per session for each argument set.

    The records of each set are written in their own directory, under the name ``simulated`` gives them.
    """
    made: dict[str, tuple[Campaign, dict]] = {}

    def records(bench: str, effects: Effects | None = None, seed: int = 0,
                nominal: Campaign | None = None) -> tuple[Campaign, dict]:
        key = repr((bench, effects, seed, nominal))  # Effects holds dicts: keyed by its repr, as exact
        if key not in made:
            made[key] = simulated(tmp_path_factory.mktemp("bench"), bench, effects, seed=seed, nominal=nominal)
        return made[key]

    return records
