"""Text and report of a diagnosis."""

from __future__ import annotations

import math


def _num(v, fmt="{:.3f}") -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else fmt.format(v)


def diagnosis_text(diagnosis) -> str:
    """Ranking, cause and gain for the terminal."""
    d = diagnosis
    n = sum(m.modes.size for m in d.measurements)
    lines = [f"Diagnosis of {d.campaign.name}: {len(d.measurements)} tests, {n} measured frequencies", ""]
    lines.append(f"{'hypothesis':<44} {'k':>3} {'chi2':>12} {'dAICc':>10} {'rms %':>8} {'cv rms %':>9}")
    best = d.ranked[0].aicc
    for f in d.ranked:
        label = " + ".join(f.effects) if f.effects else "nominal"
        lines.append(f"{label:<44} {f.n_parameters:>3} {f.chi2:>12.4g} {_num(f.aicc - best, '{:.1f}'):>10} "
                     f"{f.rms_error:>8.3f} {_num(f.cv_rms_error):>9}")
    lines += ["", "Cause: " + d.cause_text()]
    s = d.summary()["gain"]
    lines.append(f"Gain: rms error nominal {s['rms_error_nominal']:.3f} %, baseline (tension, EI) "
                 f"{_num(s.get('rms_error_baseline'))} %, corrected {s['rms_error_corrected']:.3f} %; "
                 f"cross-validated baseline {_num(s.get('cv_rms_error_baseline'))} %, corrected "
                 f"{_num(s['cv_rms_error_corrected'])} %.")
    for note in d.notes:
        lines.append(f"Note: {note}")
    for name, reason in d.skipped:
        lines.append(f"Skipped {name}: {reason}")
    return "\n".join(lines) + "\n"


def write_report(diagnosis, out_dir, spectra=()) -> None:
    """Write ``report.md`` with the tables into ``out_dir`` (placeholder until the full report lands)."""
    import os

    from ..report import write_atomic

    os.makedirs(out_dir, exist_ok=True)
    write_atomic(os.path.join(out_dir, "report.md"), "```\n" + diagnosis_text(diagnosis) + "```\n")
