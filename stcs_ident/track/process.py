"""One record of an archive into one row: its modes, their frequencies, and the tension with its 1σ.

The record's modes are picked and numbered against the cable's nominal model
at the reference tension (:func:`~stcs_ident.spectra.pipeline.analyse_record`):
numbers come from the model's family of modes, not from the order of the
peaks, so a mode missing from one record does not renumber the others. The
tension is then fitted alone (EI and everything else held at the campaign's
values) by weighted least squares on the picked frequencies
(:func:`~stcs_ident.identify.identify`), its 1σ from the fit.

Whatever goes wrong with one record (unreadable, no start time, no mode
found, a fit that fails) makes a row with status ``failed`` and the reason;
the other records go on.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

from ..core.errors import ComputationError, InputError, one_line
from ..core.model import Test
from ..identify import identify
from ..io.records import read_record
from ..spectra.pipeline import analyse_record
from .archive import CableSpec

__all__ = ["COLUMNS", "process_record"]

#: The columns of a row, in order.
#: Modes picked per record: a tension needs a few well-located modes, not the tens a long stay shows below
#: the Nyquist frequency (15 give a 1σ of about 0.04 % on a 120 m stay, far below the record-to-record
#: scatter of a tension, and take half the time of 30).
MAX_MODES = 15

COLUMNS = ("cable", "record", "record_id", "start_time", "temperature", "status", "reason", "n_modes", "modes",
           "frequencies", "frequency_sigma", "tension", "tension_sigma")


def process_record(spec: CableSpec, path: str, record_id: str) -> dict:
    """The row of the record at ``path`` (see the module docstring)."""
    relative = Path(path).relative_to(spec.directory).as_posix()
    row = {"cable": spec.name, "record": relative, "record_id": record_id, "start_time": None,
           "temperature": math.nan, "status": "failed", "reason": "", "n_modes": 0, "modes": [],
           "frequencies": [], "frequency_sigma": [], "tension": math.nan, "tension_sigma": math.nan}
    try:
        record = read_record(path, positions=dict(spec.channels) or None, directions=dict(spec.directions) or None,
                             **dict(spec.record_format))
        row["start_time"] = record.start_time
        row["temperature"] = math.nan if record.temperature is None else float(record.temperature)
        if record.start_time is None:
            raise InputError("has no start_time: a record of an archive needs one", field="start_time", file=path)
        # The record as a test of the cable's campaign: its setup, the reference tension, its path in the campaign.
        test = Test(name=relative, setup=spec.setup, tension=spec.reference_tension, record=relative,
                    channels=spec.channels, record_format=spec.record_format,
                    channel_directions=spec.directions)
        campaign = replace(spec.campaign, tests=(test,))
        spectra = analyse_record(campaign, test, record, path, max_modes=MAX_MODES)
        if not spectra.modes:
            raise ComputationError("no mode found in the record")
        row.update(n_modes=len(spectra.modes), modes=[int(m) for m in spectra.modes],
                   frequencies=[float(f) for f in spectra.frequencies],
                   frequency_sigma=[float(s) for s in spectra.uncertainty])
        # Per record: the plausibility check is off (a cable that lost half its tension is a finding to report,
        # not a unit slip to refuse), and the tolerances of EI and the length stay out of the record's σ: they
        # shift every record of the cable alike, a common bias that is no change (docs/track.md).
        result = identify(campaign, [test.name], "tension", picked={test.name: spectra}, tolerances=False,
                          check_plausibility=False)
        tension, sigma = result.value("tension")
        row.update(tension=tension, tension_sigma=sigma, status="ok")
    except (InputError, ComputationError, FloatingPointError) as err:
        row["reason"] = one_line(str(err))
    except Exception as err:  # noqa: BLE001 (one record never stops an archive: its row says what happened)
        row["reason"] = one_line(f"{type(err).__name__}: {err}")
    return row
