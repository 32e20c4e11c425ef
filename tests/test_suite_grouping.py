"""The suite's own machinery: tests of one ``xdist_group`` run on one worker under ``-n`` (``--dist loadgroup``), so
a module fixture they share is made once (tests/conftest.py's ``pytest_collection_modifyitems``: with pytest 9.2
and pytest-xdist 3.8 the groups were silently ignored and the planes' acceptance records analysed twice)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

SUITE = '''
import os, time
import pytest

@pytest.fixture(scope="module")
def made(tmp_path_factory):
    with open(os.environ["MADE_LOG"], "a") as log:
        log.write(os.environ.get("PYTEST_XDIST_WORKER", "main") + "\\n")
    time.sleep(0.5)

def test_free_1(): time.sleep(0.1)
def test_free_2(): time.sleep(0.1)
def test_free_3(): time.sleep(0.1)
def test_free_4(): time.sleep(0.1)

@pytest.mark.xdist_group("shared")
def test_grouped_1(made): pass

@pytest.mark.xdist_group("shared")
def test_grouped_2(made): pass

@pytest.mark.xdist_group("shared")
def test_grouped_3(made): pass
'''


@pytest.mark.slow  # about 10 s: two workers started, each importing the package
def test_a_group_s_module_fixture_is_made_once_under_two_workers(tmp_path):
    pytest.importorskip("xdist")
    (tmp_path / "test_grouped.py").write_text(SUITE, encoding="utf-8")
    (tmp_path / "conftest.py").write_text("from tests.conftest import pytest_collection_modifyitems  # noqa: F401\n",
                                          encoding="utf-8")
    log = tmp_path / "made.log"
    env = {**os.environ, "MADE_LOG": str(log), "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "2", "--dist", "loadgroup", "-p", "no:cacheprovider",
                           "-p", "no:randomly", "test_grouped.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "7 passed" in done.stdout
    assert log.read_text().split() in (["gw0"], ["gw1"])  # once, on one worker
