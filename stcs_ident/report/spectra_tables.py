"""The ``spectra`` table: the numbered modes picked from each test's record, as CSV.

The numbers come from each result's ``to_dataframe()`` and fields; this
module only stacks them into one table (one row per test and mode).
"""

from __future__ import annotations

import os

import numpy as np
import pandas as pd

from ..core import files

__all__ = ["MODES_CSV", "modes_table", "write_modes_csv"]

#: File name of the table, in the ``--plot`` directory.
MODES_CSV = "modes.csv"
_COLUMNS = ["test", "record_kind", "mode", "frequency_Hz", "uncertainty_Hz", "damping", "damping_uncertainty",
            "doubtful", "channels"]


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
        ``uncertainty_Hz`` (1σ), ``damping`` (ratio, NaN where not estimated), ``damping_uncertainty``
        (1σ), ``doubtful`` (the mode number is doubtful) and ``channels`` (where the peak was seen,
        space-separated).
    """
    frames = []
    for r in results:
        frame = r.to_dataframe()
        damping_sigma = np.full(len(r.modes), np.nan) if r.damping_uncertainty is None else r.damping_uncertainty
        frame.insert(0, "test", r.name)
        frame.insert(1, "record_kind", r.peaks.kind)
        frame["damping_uncertainty"] = np.asarray(damping_sigma, float)
        frames.append(frame)
    if not frames:
        return pd.DataFrame(columns=_COLUMNS)
    return pd.concat(frames, ignore_index=True)[_COLUMNS]


def write_modes_csv(results, directory: str | os.PathLike) -> str:
    """:func:`modes_table` as ``directory/modes.csv``, whole or not at all; returns the path."""
    path = os.path.join(directory, MODES_CSV)
    files.write_csv(modes_table(results), path, index=False)
    return path
