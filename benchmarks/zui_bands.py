"""The practical formulas of Zui, Shinke & Namita (1996) against the exact model: each row's error band.

Zui, H., Shinke, T., Namita, Y. (1996). Practical formulas for estimation of cable tension by vibration
method. J. Struct. Eng. (ASCE) 122(6), 651–656; the paper itself could not be read, its coefficients are as
quoted by the public implementation GitHub Levi-Ackerman/TumuWithoutTCP, src/edu/scut/se/lee/util/Data.java,
function getForce3 (introduced in commit bd9e913, unchanged at 42e749b); see stcs_ident/identify/zui.py.

What it measures: the exact frequencies of a clamped-clamped tensioned beam without sag (the dynamic-stiffness
solver, out-of-plane family) for tensions spanning ξ = l √(T/EI) from 0.05 to 10⁴ (modes 1 and 2) and from 180
to 10⁵ (modes 3 to 60), log-spaced; each frequency through :func:`stcs_ident.identify.zui.settle_row` (the
iteration between rows of ``zui_tension``); the error T_zui / T_true − 1 binned by the row the iteration
settles in and the interval of :data:`~stcs_ident.identify.zui.ERROR_BANDS` (or excluded part) its own ξ falls
in (ξ/n for the mode-n row). T_zui/T_true depends on ξ (and n) alone, so one cable (l, m, EI) suffices
(tests/test_zui.py checks a second). Printed per row and interval: the samples, the largest |error|, the mean
signed error (the formula's bias), the band stated in ERROR_BANDS and the band this run measures (the
largest |error| rounded up to two significant digits); the exit status is 1 if any stated band is below the
measured largest error. ``--write`` rewrites the marked section of docs/tension.md with the table.

    python benchmarks/zui_bands.py [--points N] [--write]
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import CHECKOUT, print_header

from stcs_ident.core.model import Boundary, Cable
from stcs_ident.forward.dsm import batch_frequencies
from stcs_ident.identify.zui import ERROR_BANDS, EXCLUDED, MAX_MODE, ROWS, band_index, settle_row

DOCS = CHECKOUT / "docs" / "tension.md"
MARK_OPEN = re.compile(r"<!-- zui-bands:[^>]*-->\n")
MARK_CLOSE = "<!-- /zui-bands -->"
COMMAND = "python benchmarks/zui_bands.py --write"

LENGTH, MASS, EI = 100.0, 50.0, 1.0e5  # one cable: the error is a function of ξ (and n) alone
XI_LOW_MODES_12 = (0.05, 1.0e4)  # the top rows' error falls as 1/ξ beyond (and is below 0.05 % there)
XI_MODE_N = (180.0, 1.0e5)  # from below 200: an answer's ξ may exceed the true one
N_MODE_N = range(3, MAX_MODE + 1)


def ceil_significant(x: float, digits: int = 2) -> float:
    """``x`` > 0 rounded up to ``digits`` significant digits (0.02214 → 0.023)."""
    if x <= 0:
        return 0.0
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(x)))
    return math.ceil(round(x * scale, 9)) / scale


def exact_frequencies(xi: np.ndarray, n_modes: int, length: float = LENGTH, mass: float = MASS,
                      EI: float = EI) -> tuple[np.ndarray, np.ndarray]:
    """(tensions, frequencies of shape (len(xi), n_modes)) of the clamped, sag-free beam at these ξ."""
    cable = Cable(length, mass, EI, None, 0.0, boundary_a=Boundary.clamped(), boundary_b=Boundary.clamped())
    tension = EI * (np.asarray(xi, float) / length) ** 2
    return tension, batch_frequencies(cable, [], tension, n_modes, plane="out")


def samples(points: int) -> list[tuple[str, int | None, int, float, float]]:
    """(row label, interval index or None for the excluded part, mode, answer's ξ, error) of every sweep point
    the iteration settles in a row with a positive tension; ``points`` ξ values per family."""
    out = []
    xi = np.geomspace(*XI_LOW_MODES_12, points)
    tension, f = exact_frequencies(xi, 2)
    cases = [(mode, t, f[i, mode - 1]) for mode in (1, 2) for i, t in enumerate(tension)]
    xi_n = np.geomspace(*XI_MODE_N, max(points // 20, 50))
    tension_n, f_n = exact_frequencies(xi_n, MAX_MODE)
    cases += [(n, t, f_n[i, n - 1]) for n in N_MODE_N for i, t in enumerate(tension_n)]
    for mode, t, freq in cases:
        row, t_zui, xi_zui, _ = settle_row(LENGTH, MASS, float(freq), mode, EI)
        if row is not None and t_zui > 0:
            out.append((row.label, band_index(row, xi_zui, mode), mode, xi_zui, t_zui / t - 1))
    return out


def table(points: int) -> list[dict]:
    """One dict per row and interval (the excluded part first), in the order of ROWS."""
    by_bin: dict[tuple[str, int | None], list[float]] = {}
    for label, index, _, _, error in samples(points):
        by_bin.setdefault((label, index), []).append(error)
    lines = []
    for row in ROWS:
        variable = "ξ/n" if row.mode is None else "ξ"
        parts = [(None, *EXCLUDED[row.label][:2])] if row.label in EXCLUDED else []
        parts += [(i, low, high) for i, (low, high, _) in enumerate(ERROR_BANDS[row.label])]
        for index, low, high in parts:
            errors = np.array(by_bin.get((row.label, index), []))
            measured = float(np.max(np.abs(errors))) if errors.size else math.nan
            lines.append({
                "row": row.label, "mode": "n ≥ 3" if row.mode is None else str(row.mode), "variable": variable,
                "low": low, "high": high, "samples": int(errors.size), "max": measured,
                "bias": float(np.mean(errors)) if errors.size else math.nan,
                "stated": None if index is None else ERROR_BANDS[row.label][index][2],
                "rounded": ceil_significant(measured) if errors.size else math.nan,
            })
    return lines


def _interval(line: dict) -> str:
    low, high, v = line["low"], line["high"], line["variable"]
    if math.isinf(high):
        return f"{v} ≥ {low:g}"
    if line["stated"] is None:  # an excluded part, from 0
        return f"{v} < {high:g}"
    last = ERROR_BANDS[line["row"]][-1][:2] == (low, high)
    return f"{low:g} ≤ {v} {'≤' if last else '<'} {high:g}"


def _band(x: float) -> str:
    """A band (two significant digits) in %, its trailing zero kept: 3.0 %, 0.095 %, 11 %."""
    percent = 100 * x
    return f"{percent:.0f} %" if percent >= 10 else f"{percent:#.2g} %"


def _percent(x: float, digits: int = 3) -> str:
    return "—" if x is None or math.isnan(x) else f"{100 * x:.{digits}g} %"


def _quoted(line: dict) -> str:
    """The row's range as the paper gives it: "17 ≤ ξ ≤ 60"."""
    return line["row"].split(", ", 1)[1].replace(">=", "≥").replace("<=", "≤").replace("xi", "ξ")


def markdown(lines: list[dict]) -> str:
    """The band table in markdown (the row's ξ range as quoted, the interval of the answer's ξ)."""
    out = ["| mode | row (as quoted) | answer's interval | samples | max \\|error\\| | mean error (bias) | band |",
           "|---|---|---|---|---|---|---|"]
    for line in lines:
        band = "left out" if line["stated"] is None else _band(line["stated"])
        out.append(f"| {line['mode']} | {_quoted(line)} | {_interval(line)} | {line['samples']} | {_percent(line['max'])} "
                   f"| {_percent(line['bias'])} | {band} |")
    return "\n".join(out)


def docs_section(lines: list[dict], points: int) -> str:
    """The text between the markers of docs/tension.md (every number from ``lines`` or the sweep's settings)."""
    worst = max((line for line in lines if line["stated"] is not None and line["variable"] == "ξ"),
                key=lambda line: line["stated"])
    return f"""Zui, Shinke & Namita (1996) give the tension from one frequency of mode 1, of mode 2
or, on long cables (ξ ≥ 200), of a mode n ≥ 3, with the length, the mass per length and EI: each mode
has a few closed-form rows, chosen by ξ = l √(T/EI). Source: Zui, H., Shinke, T., Namita, Y. (1996).
Practical formulas for estimation of cable tension by vibration method. *J. Struct. Eng.* (ASCE) 122(6),
651–656. The paper itself could not be read; the coefficients are as quoted by the public
implementation GitHub `Levi-Ackerman/TumuWithoutTCP`, `src/edu/scut/se/lee/util/Data.java`, function
`getForce3` (introduced in commit bd9e913, unchanged at 42e749b). They are in
`stcs_ident.identify.zui` (`zui_tension`). ξ depends on T, so the row is found by iteration from the
taut string; where two rows send each other across their shared end (mode 1 at ξ = 6) the one whose
ξ lies nearest its own range is used, and the answer says so.

Their accuracy is measured here, not taken from the paper: against the exact dynamic-stiffness model
of a beam with clamped ends and no sag (out-of-plane family), {points:,} log-spaced ξ from 0.05 to 10⁴
for modes 1 and 2 and {max(points // 20, 50):,} from 180 to 10⁵ for each mode 3 to {MAX_MODE}. Each error
is binned by the row the iteration settles in and the interval the answer's own ξ falls in (ξ/n for
the mode-n row: its error grows as (nπ/ξ)², a bending term the formula lacks); "band" is the largest
|T_zui/T_true − 1| there rounded up, and is what an answer carries.
The largest band of modes 1 and 2 is {_band(worst["stated"])}: mode {worst["mode"]}, row {_quoted(worst)}, at {_interval(worst)}.
Just above ξ = 17 (modes 1 and 2) the row below holds its own ξ too and is the closer of the two,
but the iteration, coming down from the taut string, settles in the upper row first. Where a row is
beyond use ("left out": the tension tending to 0 at small ξ, or ξ/n < 10) there is no answer.
Sag (Irvine's λ²) is not taken into account: the paper chooses between the mode-1 and mode-2 sets by
a sag parameter Γ whose definition could not be verified, so no sag criterion is applied, and the
bands are those of a cable without sag. Mehrabi & Tabatabai (1998) is left out: no source of its
coefficients could be read.

{markdown(lines)}

Regenerate with `{COMMAND}`.
"""


def bands_source(lines: list[dict]) -> str:
    """ERROR_BANDS with this run's bands, as Python source (the intervals as they are)."""
    out = ["ERROR_BANDS = {"]
    for row in ROWS:
        items = [f"({line['low']!r}, {'math.inf' if math.isinf(line['high']) else repr(line['high'])}, "
                 f"{line['rounded']!r})" for line in lines if line["row"] == row.label and line["stated"] is not None]
        out.append(f"    {row.label!r}: ({', '.join(items)},),")
    return "\n".join([*out, "}"])


def write_docs(text: str, path: Path = DOCS) -> None:
    """Replace exactly the text between the zui-bands markers of ``path``."""
    content = path.read_text(encoding="utf-8")
    opening = MARK_OPEN.search(content)
    close = content.find(MARK_CLOSE)
    if opening is None or close < opening.end():
        raise SystemExit(f"{path}: the markers <!-- zui-bands: ... --> and {MARK_CLOSE} were not found in order")
    path.write_text(content[:opening.end()] + text + content[close:], encoding="utf-8")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=20000,
                        help=f"log-spaced ξ values for modes 1 and 2 (a twentieth of them, at least 50, for each "
                             f"mode 3-{MAX_MODE}; default 20000)")
    parser.add_argument("--write", action="store_true", help=f"rewrite the zui-bands section of {DOCS.name}")
    args = parser.parse_args(argv)
    print_header()
    start = time.perf_counter()
    lines = table(args.points)
    print(markdown(lines))
    print(f"\n{time.perf_counter() - start:.1f} s")
    loose = [line for line in lines if line["stated"] is not None and line["samples"] == 0]
    broken = [line for line in lines if line["stated"] is not None and line["max"] > line["stated"]]
    differ = [line for line in lines if line["stated"] is not None and line["samples"]
              and line["rounded"] != line["stated"]]
    for line in loose:
        print(f"no sample in {line['row']}, {_interval(line)}: refine --points")
    for line in differ:
        print(f"{line['row']}, {_interval(line)}: stated {line['stated']:g}, measured rounded up {line['rounded']:g}")
    if differ:
        print("\nERROR_BANDS as measured (stcs_ident/identify/zui.py):")
        print(bands_source(lines))
    if broken:
        print(f"{len(broken)} stated band(s) below the measured error: update ERROR_BANDS in "
              f"stcs_ident/identify/zui.py")
    if args.write:
        write_docs(docs_section(lines, args.points))
        print(f"wrote the zui-bands section of {DOCS}")
    return 1 if broken or loose else 0


if __name__ == "__main__":
    sys.exit(main())
