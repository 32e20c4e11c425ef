"""Human-readable tables of ``forward`` and the package's atomic output files.

Tables are built from the result objects' data and formatted here; output
files are written whole or not at all (a temporary file in the target
directory, then an atomic rename).
"""

from __future__ import annotations

from ..core.files import replace_directory, write_atomic  # noqa: F401  (re-exported: the writers of the package)
from ..core.formatting import number, rms
from ..core.planes import PLANE_NAMES
from ..forward.compare import ForwardResult
from .spectra_tables import spectra_text  # noqa: F401  (re-exported: the spectra command's text is written there)


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
