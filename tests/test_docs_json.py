"""The JSON examples of the docs hold: each ```json block of docs/formats.md and docs/track.md against a real
run's JSON, key by key and value by value.

An example is abridged: ``...`` stands for what is left out (a list's further items, a value, a part of a
string). Every key an example shows must be in the real JSON; every number it shows must agree with the real
one to the digits it prints (and within 0.5 %: an example rounded to three digits is not stale for that);
strings must agree (around their ``...``).
"""

from __future__ import annotations

import json
import re
from decimal import Decimal
from pathlib import Path

import pytest

import stcs_ident as si
from stcs_ident.cli.common import to_json
from stcs_ident.spectra.pipeline import campaign_summary

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"^```json\n(.*?)^```", re.DOTALL | re.MULTILINE)
ELLIPSIS = "\u2026left out\u2026"
#: A number agrees when within half a unit of its last printed digit or this relative amount (an example's
#: rounding), whichever is larger; a stale example (han2020's 3.86 kg against 3.83) is 0.8 % off.
RELATIVE = 0.005


def _blocks(page: str) -> list[str]:
    return BLOCK.findall((ROOT / "docs" / page).read_text(encoding="utf-8"))


def parse_example(text: str):
    """The example as data: a bare ``...`` (outside strings) becomes :data:`ELLIPSIS`; numbers keep their digits."""
    out, in_string, i, stack = [], False, 0, []
    while i < len(text):
        c = text[i]
        if c == '"' and (i == 0 or text[i - 1] != "\\"):
            in_string = not in_string
        if not in_string:
            if text.startswith("...", i):  # a member of a mapping left out, or an item or a value
                left = json.dumps(ELLIPSIS)
                member = stack and stack[-1] == "{" and "".join(out).rstrip()[-1:] in ("{", ",")
                out.append(f"{left}: {left}" if member else left)
                i += 3
                continue
            if c in "[{":
                stack.append(c)
            elif c in "]}":
                stack.pop()
        out.append(c)
        i += 1
    return json.loads("".join(out), parse_float=Decimal)


def agree(example, real, where="") -> list[str]:
    """Where ``example`` and ``real`` disagree (empty: they agree)."""
    if example == ELLIPSIS:
        return []
    if isinstance(example, dict):
        if not isinstance(real, dict):
            return [f"{where}: a mapping in the example, {type(real).__name__} in the run"]
        wrong = []
        for key, value in example.items():
            if key == ELLIPSIS:
                continue
            if key not in real:
                wrong.append(f"{where}.{key}: not in the run's JSON")
                continue
            wrong += agree(value, real[key], f"{where}.{key}")
        return wrong
    if isinstance(example, list):
        if not isinstance(real, list):
            return [f"{where}: a list in the example, {type(real).__name__} in the run"]
        shown = [v for v in example if v != ELLIPSIS]
        if ELLIPSIS not in example and len(example) != len(real):
            return [f"{where}: {len(example)} items in the example, {len(real)} in the run"]
        if len(shown) > len(real):
            return [f"{where}: {len(shown)} items shown, {len(real)} in the run"]
        if example and example[0] == ELLIPSIS:  # ``[..., item, ...]``: an item from within the list
            return [f"{where}: {v!r} agrees with no item of the run's" for v in shown
                    if all(agree(v, r) for r in real)]
        return [w for k, v in enumerate(shown) for w in agree(v, real[k], f"{where}[{k}]")]
    if isinstance(example, bool) or example is None:
        return [] if example is real or example == real else [f"{where}: {example!r} in the example, {real!r} in the run"]
    if isinstance(example, Decimal | int):
        if isinstance(real, bool) or not isinstance(real, int | float):
            return [f"{where}: {example} in the example, {real!r} in the run"]
        digits = -example.as_tuple().exponent if isinstance(example, Decimal) else 0
        tolerance = max(0.5 * 10.0 ** (-digits), RELATIVE * abs(float(example)))
        return [] if abs(float(example) - real) <= tolerance else [f"{where}: {example} in the example, {real} in the run"]
    if isinstance(example, str):
        parts = example.split("...")
        if len(parts) == 1:
            return [] if example == real else [f"{where}: {example!r} in the example, {real!r} in the run"]
        pattern = ".*".join(re.escape(p) for p in parts)
        return [] if isinstance(real, str) and re.fullmatch(pattern, real, re.DOTALL) else [
            f"{where}: {example!r} in the example, {real!r} in the run"]
    return [f"{where}: {example!r} of an unknown kind"]


def _run(summary: dict) -> dict:
    return json.loads(to_json(summary))


def test_the_parser_and_the_comparison_can_fail():
    example = parse_example('{"a": [1.25, ...], "b": "x ... z", "c": {"d": ..., "e": true}}')
    assert agree(example, {"a": [1.2504, 9], "b": "x y z", "c": {"d": 3, "e": True}, "f": 1}) == []
    assert agree(example, {"a": [1.30, 9], "b": "x y z", "c": {"d": 3, "e": True}})  # a stale number
    assert agree(example, {"a": [1.25], "b": "y z", "c": {"d": 3, "e": True}})  # a string that changed
    assert agree(example, {"a": [1.25], "b": "x y z", "c": {"e": True}})  # a key gone
    inside = parse_example('[..., {"k": 2}, ...]')
    assert agree(inside, [{"k": 1}, {"k": 2}]) == [] and agree(inside, [{"k": 1}, {"k": 3}])


@pytest.mark.slow
def test_the_formats_page_examples_hold():
    forward, spectra, identify, diagnose = _blocks("formats.md")
    han = si.load_campaign(ROOT / "campaigns" / "han2020")
    hidden = si.load_campaign(ROOT / "campaigns" / "hanger-hidden-mass")
    runs = {
        "forward": (forward, _run(si.compare_forward(han, ["case1-L4", "case1-L5"]).summary())),
        "spectra": (spectra, _run(campaign_summary(hidden.name, si.analyse_campaign(hidden), []))),
        "identify": (identify, _run(si.identify(han, ["case1-L4", "case1-L5"], "tension,EI").summary())),
        # the shipped report's JSON: tests/test_reports.py holds it equal to a fresh run of the main job
        "diagnose": (diagnose, json.loads((ROOT / "reports" / "han2020.json").read_text(encoding="utf-8"))),
    }
    wrong = {name: agree(parse_example(block), real) for name, (block, real) in runs.items()}
    assert not any(wrong.values()), wrong


@pytest.mark.slow
def test_the_track_page_example_has_the_keys_of_a_run(tmp_path):
    """The track page's example is of a week-long archive of a bare and a damped stay (not shipped): its keys
    are checked against a run of a small simulated archive of both; its values are the page's."""
    from stcs_ident.simulate.archive import ArchiveOptions, simulate_archive
    from tests.test_track import _campaign

    (block,) = _blocks("track.md")
    example = parse_example(block)
    simulate_archive({"C2": _campaign(tmp_path / "campaign")}, tmp_path / "archive",
                     options=ArchiveOptions(days=0.25, interval=1800), seed=5)
    real = _run(si.track(tmp_path / "archive", tmp_path / "out", workers=1).summary())
    keys_only = {"archive": ELLIPSIS, "cables": {"C2": {k: ELLIPSIS for k in example["cables"]["C2"]}}}
    assert agree(keys_only, real) == []
    assert set(example) == set(real)
