"""One record of an archive into one row: its modes (with their planes), their frequencies, and the tension
with its 1σ.

The record's modes are picked and numbered against the cable's nominal model
at the reference tension (:func:`~stcs_ident.spectra.pipeline.analyse_record`):
numbers come from the model's family of modes, not from the order of the
peaks, so a mode missing from one record does not renumber the others; each
mode is of one plane (``planes``: ``"in"`` or ``"out"``, from the channels'
directions), numbered within it. A mode whose number the numbering calls
doubtful (another family of modes, at another tension, fits the peaks
almost as well: a short record with one or a few peaks) is kept in the row
and flagged (``doubtful``), but left out of the fits; a record whose every
number is doubtful gives no tension (status ``failed``, the reason says
so) rather than one of several, each with a small σ. The tension is then fitted alone (EI and everything else
held at the campaign's values) by weighted least squares on the picked frequencies
(:func:`~stcs_ident.identify.identify`, each mode against its plane's
model), its 1σ from the fit.

Each mode's damping ratio and its 1σ (``damping_ratio``, ``damping_ratio_sigma``, aligned
with ``modes``; NaN where the spectra estimated none) are kept as the spectra
gave them. For a cable whose setup has one :class:`~stcs_ident.core.model.Damper`,
its coefficient is then fitted jointly with the tension from the
frequencies and the damping ratios (``identify(..., "tension,coefficient")``,
as ``identify --params tension,coefficient`` does), with its 1σ
(``coefficient_Ns_per_m``, ``coefficient_sigma_Ns_per_m``); the tension of that joint fit is
the row's. A joint fit that stops at a bound, is not identifiable or fails
otherwise leaves the coefficient NaN with its reason
(``coefficient_reason``) and the tension of the tension-only fit. A setup
with several dampers is not fitted for a coefficient (identify would free
one per damper, which one record's damping ratios rarely separate):
``coefficient_reason`` says so. Without a damper the columns are NaN and
the reason empty.

Whatever goes wrong with one record (unreadable, no start time, no mode
found, a fit that fails or gives no finite tension and 1σ) makes a row with
status ``failed`` and the reason;
the other records go on.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from pathlib import Path

from ..core.errors import ComputationError, InputError, one_line
from ..core.model import Damper, Test
from ..identify import IdentifiabilityWarning, identify
from ..identify.plausibility import check_records
from ..io.test_record import open_test_record
from ..spectra.pipeline import analyse_record
from .archive import CableSpec

__all__ = ["COLUMNS", "process_record"]

#: Modes picked per record: a tension needs a few well-located modes, not the tens a long stay shows below
#: the Nyquist frequency (15 give a 1σ of about 0.04 % on a 120 m stay, far below the record-to-record
#: scatter of a tension, and take half the time of 30).
MAX_MODES = 15

#: The columns of a row, in order; a quantity's name ends with its unit (``_degC``, ``_Hz``, ``_N``, ``_Ns_per_m``;
#: ``_ratio`` for a damping ratio). ``modes`` … ``damping_ratio_sigma`` hold one value per mode.
COLUMNS = ("cable", "record", "record_id", "start_time", "temperature_degC", "status", "reason", "n_modes", "modes",
           "planes", "frequencies_Hz", "frequency_sigma_Hz", "doubtful", "tension_N", "tension_sigma_N",
           "damping_ratio", "damping_ratio_sigma", "coefficient_Ns_per_m", "coefficient_sigma_Ns_per_m",
           "coefficient_reason")
#: The columns added with the damper's history: a part written before them reads with these defaults
#: (:mod:`.store`).
DAMPER_COLUMNS = {"damping_ratio": list, "damping_ratio_sigma": list, "coefficient_Ns_per_m": math.nan,
                  "coefficient_sigma_Ns_per_m": math.nan,
                  "coefficient_reason": ""}


def process_record(spec: CableSpec, path: str, record_id: str) -> dict:
    """The row of the record at ``path`` (see the module docstring)."""
    relative = Path(path).relative_to(spec.directory).as_posix()
    row = {"cable": spec.name, "record": relative, "record_id": record_id, "start_time": None,
           "temperature_degC": math.nan, "status": "failed", "reason": "", "n_modes": 0, "modes": [],
           "planes": [], "frequencies_Hz": [], "frequency_sigma_Hz": [], "doubtful": [], "tension_N": math.nan,
           "tension_sigma_N": math.nan, "damping_ratio": [], "damping_ratio_sigma": [],
           "coefficient_Ns_per_m": math.nan, "coefficient_sigma_Ns_per_m": math.nan,
           "coefficient_reason": ""}
    try:
        # The record as a test of the cable's campaign: its setup, the reference tension, its path in the campaign.
        test = Test(name=relative, setup=spec.setup, tension=spec.reference_tension, record=relative,
                    channels=spec.channels, record_format=spec.record_format,
                    channel_directions=spec.directions)
        campaign = replace(spec.campaign, tests=(test,), directory=spec.directory)
        path, record = open_test_record(campaign, test)
        row["start_time"] = record.start_time
        row["temperature_degC"] = math.nan if record.temperature is None else float(record.temperature)
        if record.start_time is None:
            raise InputError("has no start_time: a record of an archive needs one", field="start_time", file=path)
        spectra = analyse_record(campaign, test, record, path, max_modes=MAX_MODES)
        if getattr(spectra, "implausible_scale", ()):  # a unit or sampling-rate slip, not a change of the cable
            check_records(campaign, {test.name: spectra})
        if not spectra.modes:
            raise ComputationError("no mode found in the record")
        row.update(n_modes=len(spectra.modes), modes=[int(m) for m in spectra.modes],
                   planes=[str(p) for p in spectra.mode_planes],
                   frequencies_Hz=[float(f) for f in spectra.frequencies],
                   frequency_sigma_Hz=[float(s) for s in spectra.uncertainty],
                   doubtful=_flags(getattr(spectra, "doubtful", None), len(spectra.modes)),
                   damping_ratio=_floats(getattr(spectra, "damping", None), len(spectra.modes)),
                   damping_ratio_sigma=_floats(getattr(spectra, "damping_uncertainty", None), len(spectra.modes)))
        _some_sure(row)
        # Per record: the plausibility check is off (a cable that lost half its tension is a finding to report,
        # not a unit slip to refuse), and the tolerances of EI and the length stay out of the record's σ: they
        # shift every record of the cable alike, a common bias that is no change (docs/track.md).
        dampers = [a for a in spec.campaign.setup(spec.setup).attachments if isinstance(a, Damper)]
        if len(dampers) == 1:
            row.update(_joint_fit(campaign, test.name, spectra))
        elif dampers:
            row["coefficient_reason"] = (f"{len(dampers)} dampers ({', '.join(d.name for d in dampers)}): "
                                         "a coefficient is tracked on a cable with one damper")
        if math.isnan(row["coefficient_Ns_per_m"]):
            result = identify(campaign, [test.name], "tension", picked={test.name: spectra}, tolerances=False,
                              check_plausibility=False)
            row["tension_N"], row["tension_sigma_N"] = result.value("tension")
        if not (math.isfinite(row["tension_N"]) and math.isfinite(row["tension_sigma_N"])
                and row["tension_sigma_N"] > 0):
            # the start value with an infinite σ is no answer (the model could not be evaluated around it)
            raise ComputationError(f"no tension: the fit gave {row['tension_N']:.6g} ± {row['tension_sigma_N']:.3g} N")
        row["status"] = "ok"
    except (InputError, ComputationError, FloatingPointError) as err:
        row["reason"] = one_line(str(err))
    except Exception as err:  # noqa: BLE001 (one record never stops an archive: its row says what happened)
        row["reason"] = one_line(f"{type(err).__name__}: {err}")
    return row


def _some_sure(row: dict) -> None:
    """Refuse a record whose every mode number the numbering calls doubtful (another family of modes, at another
    tension, fits the peaks almost as well): its tension would be one of several, each stated with a small σ.
    With some sure, :func:`~stcs_ident.identify.identify` leaves the doubtful ones out of its fit itself."""
    if row["doubtful"] and all(row["doubtful"]):
        peaks = ", ".join(f"{f:.3f}" for f in row["frequencies_Hz"])
        raise ComputationError(f"the mode number of every peak ({peaks} Hz) is doubtful: another family of modes "
                               "fits almost as well, at another tension")


def _flags(values, n: int) -> list[bool]:
    """``values`` (or False each when there are none) as a list of ``n`` booleans."""
    return [False] * n if values is None else [bool(v) for v in values]


def _floats(values, n: int) -> list[float]:
    """``values`` (or NaN each when there are none) as a list of ``n`` floats."""
    return [math.nan] * n if values is None else [float(v) for v in values]


def _joint_fit(campaign, test: str, spectra) -> dict:
    """The tension and the damper's coefficient fitted together, or the coefficient's reason for failing."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", IdentifiabilityWarning)
            result = identify(campaign, [test], "tension,coefficient", picked={test: spectra}, tolerances=False,
                              check_plausibility=False)
        unidentifiable = [w for w in caught if issubclass(w.category, IdentifiabilityWarning)]
        for w in caught:  # the others go on as the tension-only fit's would
            if not issubclass(w.category, IdentifiabilityWarning):
                warnings.warn(w.message, w.category, stacklevel=2)
        if unidentifiable:
            raise ComputationError(f"not identifiable: {unidentifiable[0].message}")
        if not result.tests[0].damping:  # the frequencies alone: the coefficient only through the shifts
            raise ComputationError("no damping ratio measured")
        tension, tension_sigma = result.value("tension")
        coefficient, sigma = result.value("coefficient")
        if not (math.isfinite(coefficient) and math.isfinite(sigma) and sigma > 0):
            raise ComputationError(f"no finite coefficient ({coefficient:g} ± {sigma:g})")
    except (InputError, ComputationError, FloatingPointError) as err:  # a bound included (BoundError)
        return {"coefficient_reason": one_line(str(err))}
    return {"tension_N": tension, "tension_sigma_N": tension_sigma, "coefficient_Ns_per_m": coefficient,
            "coefficient_sigma_Ns_per_m": sigma}
