"""The ``spectra`` outputs: the numbered modes picked from each test's record, as CSV and as text.

The numbers come from each result's ``to_dataframe()`` and fields; this
module only stacks them into one table (one row per test and mode) and
writes them as the command's text.
"""

from __future__ import annotations

import math
import os

import pandas as pd

from ..core import files
from ..core.formatting import is_missing, number
from ..core.planes import PLANE_NAMES

__all__ = ["MODES_CSV", "damping_cell", "modes_table", "spectra_text", "write_modes_csv"]

#: File name of the table, in the ``--plot`` directory.
MODES_CSV = "modes.csv"
_COLUMNS = ["test", "record_kind", "mode", "frequency_Hz", "uncertainty_Hz", "damping_ratio",
            "damping_ratio_uncertainty", "doubtful", "channels", "plane", "mac"]


def modes_table(results) -> pd.DataFrame:
    """One row per test and numbered mode.

    Parameters
    ----------
    results : sequence of TestSpectra
        The picked modes of each test (``stcs_ident.spectra.pipeline``).

    Returns
    -------
    pandas.DataFrame
        Columns ``test``, ``record_kind`` (``impulse`` or ``ambient``), ``mode``, ``frequency_Hz``,
        ``uncertainty_Hz`` (1σ), ``damping_ratio`` (a ratio, not percent; NaN where not estimated),
        ``damping_ratio_uncertainty`` (1σ), ``doubtful`` (the mode number is doubtful), ``channels`` (where the
        peak was seen, joined by ``;``), ``plane`` (``in`` or ``out``: mode numbers count per plane) and ``mac`` (of the
        operating shape against the model's, NaN where not meaningful).
    """
    frames = []
    for r in results:
        frame = r.to_dataframe()
        frame.insert(0, "test", r.name)
        frame.insert(1, "record_kind", r.peaks.kind)
        frames.append(frame)
    if not frames:
        return pd.DataFrame(columns=_COLUMNS)
    return pd.concat(frames, ignore_index=True)[_COLUMNS]


def write_modes_csv(results, directory: str | os.PathLike) -> str:
    """:func:`modes_table` as ``directory/modes.csv``, whole or not at all; returns the path."""
    path = os.path.join(directory, MODES_CSV)
    files.write_csv(modes_table(results), path, index=False)
    return path


#: Width of the damping ratio and of its 1σ (in %, three decimals) in the text table's ``damping % ± 1σ``.
_DAMPING_WIDTH = 6


def damping_cell(zeta: float, sigma: float) -> str:
    """``ζ ± σ`` in % (three decimals each) with the ± at a fixed place, so that a column of them stays
    aligned: the ratio alone where its σ is missing, :data:`~stcs_ident.core.formatting.MISSING` where the
    ratio is."""
    value = number(100 * zeta, "{:.3f}", width=_DAMPING_WIDTH)
    if is_missing(zeta) or is_missing(sigma):
        return value + " " * (_DAMPING_WIDTH + 3)
    return f"{value} ± {number(100 * sigma, '{:.3f}'):<{_DAMPING_WIDTH}}"


def spectra_text(campaign: str, results, skipped) -> str:
    """The ``spectra`` tables: per test, mode (and its plane where the record has channel directions),
    frequency, uncertainty, damping ratio with its 1σ (:func:`damping_cell`), MAC, channels; then the peaks left
    unnumbered, the structural ones (the deck's or pylon's, never numbered) and the notes."""
    lines = [f"Campaign {campaign}: modal frequencies picked from the records", ""]
    for r in results:
        lines.append(f"Test {r.name} ({r.peaks.kind} record {os.path.basename(r.record)})")
        for name, reason in r.dropped:
            lines.append(f"  channel {name} dropped: {reason}")
        for option, given, found in getattr(r, "record_replaced", ()):
            lines.append(f"  record: {option} {given!r} from record_format replaces the file's {found!r}")
        planes = r.planes is not None
        table = r.to_dataframe()
        head = f"{'plane':>5} " if planes else ""
        width = 2 * _DAMPING_WIDTH + 3
        lines.append(f"{head}{'mode':>4} {'frequency':>11} {'uncertainty':>11} {'damping % ± 1σ':>{width}} {'MAC':>5}"
                     "  channels")
        for k, f, u, z, s, ch, doubt, plane, m in zip(r.modes, r.frequencies, r.uncertainty, table["damping_ratio"],
                                                      table["damping_ratio_uncertainty"], r.channels, r.doubtful,
                                                      r.mode_planes, table["mac"]):
            flag = "?" if doubt else " "
            mac = "" if math.isnan(m) else f"{m:.2f}"
            head = f"{plane:>5} " if planes else ""
            lines.append(f"{head}{k:>3}{flag} {f:11.4f} {u:11.5f} {damping_cell(z, s)} {mac:>5}  {' '.join(ch)}")
        if any(r.doubtful):
            lines.append("  ? = doubtful mode number: another family of modes fits almost as well")
        where = r.unassigned_planes or ("in",) * len(r.unassigned)
        for (f, u), plane in zip(r.unassigned, where):
            side = f" ({PLANE_NAMES[plane]})" if planes else ""
            lines.append(f"  unassigned peak at {f:.4f} ± {u:.5f} Hz{side}")
        for f, u, reason in r.structural:
            lines.append(f"  structural peak at {f:.4f} ± {u:.5f} Hz, not the cable's: {reason}")
        for note in r.notes:
            lines.append(f"  note: {note}")
        lines.append("")
    if skipped:
        lines.append(f"Tests without a record (nothing to pick): {', '.join(skipped)}")
        lines.append("")
    return "\n".join(lines)
