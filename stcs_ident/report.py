"""Human-readable tables and atomic output files.

Tables are built from the result objects' data and formatted here; output
files are written whole or not at all (a temporary file in the target
directory, then an atomic rename).
"""

from __future__ import annotations

import json
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

from .compare import ForwardResult


def _fmt(value, digits=3, width=9) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-".rjust(width)
    return f"{value:{width}.{digits}f}"


def forward_text(result: ForwardResult) -> str:
    """The ``forward`` tables: per test, measured and every model with errors in %."""
    lines = [f"Campaign {result.campaign}: nominal model (tension model '{result.tension_model}')", ""]
    for t in result.tests:
        lines.append(f"Test {t.name} (setup {t.setup}, tension {t.tension / 1e3:.1f} kN)")
        head = f"{'mode':>4} {'measured':>9} {'string':>9} {'err%':>7} {'beam':>9} {'err%':>7} {'DSM':>9} {'err%':>7}"
        refs = list(t.reference)
        widths = {label: max(len(label), 9) for label in refs}
        head += "".join(f" {label:>{widths[label]}}" for label in refs)
        lines.append(head)
        errors = {c: t.error(c) for c in ("taut_string", "beam_pinned", "dsm")}
        for i, k in enumerate(t.modes):
            row = f"{k:>4} {_fmt(None if t.measured is None else float(t.measured[i]))}"
            for col in ("taut_string", "beam_pinned", "dsm"):
                err = errors[col]
                row += f" {_fmt(float(getattr(t, col)[i]))} {_fmt(None if err is None else float(err[i]), 2, 7)}"
            row += "".join(f" {_fmt(float(t.reference[label][i]), 3, widths[label])}" for label in refs)
            lines.append(row)
        if t.measured is not None:
            rms = {c: math.sqrt(float((errors[c][~np.isnan(errors[c])] ** 2).mean())) for c in errors}
            lines.append(f"     rms error %: string {rms['taut_string']:.2f}, beam {rms['beam_pinned']:.2f}, "
                         f"DSM {rms['dsm']:.2f}")
        lines.append("")
    if result.reference_checks:
        lines.append("Reference columns:")
        for check in result.reference_checks:
            lines.append(f"- {check.sentence()}")
        lines.append("")
    return "\n".join(lines)


def write_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` whole or not at all; ``-`` is standard output."""
    if str(path) == "-":
        sys.stdout.write(text)
        return
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as stream:
            stream.write(text)
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)  # mkstemp makes 0600; give the mode a plain open() would
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def to_json(data) -> str:
    return json.dumps(data, indent=2, allow_nan=False, default=_json_default) + "\n"


def _json_default(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")
