"""Human-readable tables and atomic output files.

Tables are built from the result objects' data and formatted here; output
files are written whole or not at all (a temporary file in the target
directory, then an atomic rename).
"""

from __future__ import annotations

import json
import math
import os

from ..core.files import replace_directory, write_atomic  # noqa: F401  (re-exported: the writers of the package)
from ..core.formatting import number, rms
from ..core.planes import PLANE_NAMES
from ..forward.compare import ForwardResult


def _fmt(value, digits=3, width=9) -> str:
    return number(value, f"{{:{width}.{digits}f}}", width=width)


def forward_text(result: ForwardResult) -> str:
    """The ``forward`` tables: per test (and plane, when out-of-plane modes are asked for), measured and every
    model with errors in %."""
    lines = [f"Campaign {result.campaign}: nominal model (tension model '{result.tension_model}')", ""]
    only_in = tuple(getattr(result, "planes", ("in",))) == ("in",)
    for t in getattr(result, "comparisons", result.tests):
        plane = "" if only_in else f", {PLANE_NAMES[t.plane]}"
        lines.append(f"Test {t.name} (setup {t.setup}, tension {t.tension / 1e3:.1f} kN){plane}")
        head = f"{'mode':>4} {'measured':>9} {'string':>9} {'err%':>7} {'beam':>9} {'err%':>7} {'DSM':>9} {'err%':>7}"
        refs = list(t.reference)
        widths = {label: max(len(label), 9) for label in refs}
        head += "".join(f" {label:>{widths[label]}}" for label in refs)
        if t.damping is not None:
            head += f" {'DSM ζ %':>8}"
        lines.append(head)
        errors = {c: t.error(c) for c in ("taut_string", "beam_pinned", "dsm")}
        for i, k in enumerate(t.modes):
            row = f"{k:>4} {_fmt(None if t.measured is None else float(t.measured[i]))}"
            for col in ("taut_string", "beam_pinned", "dsm"):
                err = errors[col]
                row += f" {_fmt(float(getattr(t, col)[i]))} {_fmt(None if err is None else float(err[i]), 2, 7)}"
            row += "".join(f" {_fmt(float(t.reference[label][i]), 3, widths[label])}" for label in refs)
            if t.damping is not None:
                row += f" {_fmt(100 * float(t.damping[i]), 3, 8)}"
            lines.append(row)
        if t.measured is not None:
            errs = {c: rms(errors[c]) for c in errors}
            lines.append(f"     rms error %: string {errs['taut_string']:.2f}, beam {errs['beam_pinned']:.2f}, "
                         f"DSM {errs['dsm']:.2f}")
        lines.append("")
    if result.reference_checks:
        lines.append("Reference columns:")
        for check in result.reference_checks:
            lines.append(f"- {check.sentence()}")
        lines.append("")
    return "\n".join(lines)


def to_json(data) -> str:
    """``data`` as standard JSON: a value that is not a finite number (a σ the data cannot give, an error
    against a reference of 0) is written as null, never as NaN or Infinity, which JSON does not have."""
    return json.dumps(_finite_or_null(data), indent=2, allow_nan=False, default=_json_default) + "\n"


def _finite_or_null(value):
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite_or_null(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_or_null(v) for v in value]
    if hasattr(value, "tolist") and not isinstance(value, str):
        return _finite_or_null(value.tolist())
    return value


def _json_default(value):
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def spectra_text(campaign: str, results, skipped) -> str:
    """The ``spectra`` tables: per test, mode, frequency, uncertainty, channels."""
    lines = [f"Campaign {campaign}: modal frequencies picked from the records", ""]
    for r in results:
        lines.append(f"Test {r.name} ({r.peaks.kind} record {os.path.basename(r.record)})")
        for name, reason in r.dropped:
            lines.append(f"  channel {name} dropped: {reason}")
        for option, given, found in getattr(r, "record_replaced", ()):
            lines.append(f"  record: {option} {given!r} from record_format replaces the file's {found!r}")
        lines.append(f"{'mode':>4} {'frequency':>11} {'uncertainty':>11} {'damping %':>9}  channels")
        for k, f, u, z, ch, doubt in zip(r.modes, r.frequencies, r.uncertainty, r.damping, r.channels, r.doubtful):
            flag = "?" if doubt else " "
            zeta = number(100 * z, "{:.2f}")
            lines.append(f"{k:>3}{flag} {f:11.4f} {u:11.5f} {zeta:>9}  {' '.join(ch)}")
        if any(r.doubtful):
            lines.append("  ? = doubtful mode number: another family of modes fits almost as well")
        for f, u in r.unassigned:
            lines.append(f"  unassigned peak at {f:.4f} ± {u:.5f} Hz")
        lines.append("")
    if skipped:
        lines.append(f"Tests without a record (nothing to pick): {', '.join(skipped)}")
        lines.append("")
    return "\n".join(lines)
