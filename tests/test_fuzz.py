"""Fuzzing the command line: every bad input is a clean refusal, no input is ever modified.

tests/fuzz_inputs.py generates the cases (a mutated campaign file, record or
option; its docstring lists the kinds and the outcomes). Each kind has a
test of its own (the findings that started it: an integer beyond float
range, a 5000-digit literal, arrays nested 5000 deep, corrupt HDF5 with bit
flips and links of every kind, a Nyquist-alternating record, 2000
attachments, a mode number of 2⁶², frequencies of 1e300, a name with a
newline, outputs pointed at the inputs, sizes no machine can simulate...),
and a seeded run of mixed cases is bounded in time. The long run (≥ 5000
inputs) is benchmarks/fuzz.py.
"""

from __future__ import annotations

import random

import pytest

from tests.fuzz_inputs import FINDINGS, KINDS, make_case, run, run_case

#: Seconds one case may take: the slowest correct run here (a diagnosis of the small campaign) takes
#: about 10 s on a loaded 2-core machine; a hang is anything far beyond.
TIME_LIMIT = 60.0


@pytest.mark.parametrize("kind", KINDS)
def test_each_kind_of_bad_input_is_refused_cleanly_and_leaves_the_inputs(kind, tmp_path):
    for seed in (0, 1):
        case = make_case(seed, KINDS.index(kind), tmp_path, kind)
        outcome = run_case(case, TIME_LIMIT)
        assert outcome.status not in FINDINGS, (outcome.status, case.argv, outcome.stderr[-2000:])


def test_a_seeded_mix_of_inputs_gives_no_finding(tmp_path):
    """150 cases of seed 20261201 (every kind at least twice)."""
    outcomes = run(20261201, 150, tmp_path, TIME_LIMIT)
    findings = [(o.case.kind, o.status, o.case.argv, o.stderr[-500:]) for o in outcomes if o.status in FINDINGS]
    assert not findings
    statuses = {o.status for o in outcomes}
    assert {"ok", "refused"} <= statuses  # the generator makes both good and bad inputs


def test_the_generator_is_reproducible(tmp_path):
    a = make_case(5, 7, tmp_path / "a")
    b = make_case(5, 7, tmp_path / "b")
    assert a.kind == b.kind
    assert (a.directory / "campaign.toml").read_bytes() == (b.directory / "campaign.toml").read_bytes()
    assert random.Random("5:7").random() == random.Random("5:7").random()
