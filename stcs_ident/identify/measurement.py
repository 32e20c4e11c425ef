"""Measured natural frequencies of a test, with their uncertainties and planes.

:class:`Measurement` holds one test's measured modes with a standard
uncertainty per mode: from the spectra of a record, given by the caller,
or, for a table of frequencies, the rounding of the table (a value printed
to 0.01 Hz is uniform within ±0.005 Hz: standard uncertainty 0.01/√12 Hz).
Each mode is of one plane, in-plane (``"in"``) or out-of-plane (``"out"``),
numbered within it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..core.errors import InputError
from ..core.model import Campaign, Test
from ..core.notes import Note
from ..core.planes import PLANE_NAMES, PLANES


@dataclass(frozen=True)
class Measurement:
    """Measured natural frequencies of one test.

    Attributes
    ----------
    test : Test
    modes : ndarray of int
    frequencies : ndarray
        Hz, ordered by ``modes``.
    uncertainty : ndarray
        Standard uncertainty of each frequency, Hz (> 0).
    source : str
        Where the uncertainty comes from: ``"spectra"``, ``"table rounding
        (0.01 Hz / sqrt 12)"`` or ``"given"``.
    damping, damping_uncertainty : ndarray or None
        Measured damping ratios and their 1σ, ordered by ``modes`` (NaN
        where not measured); used with a damper in the model.
    damping_is_data : bool or None
        Whether a :class:`Problem` of these measurements takes the damping
        ratios as data (the diagnosis decides it once for every hypothesis);
        None: with a damper in the model.
    planes : ndarray of str or None
        The plane of each mode, ``"in"`` or ``"out"`` (given in the order of
        ``modes``; None: all in-plane). Mode numbers are distinct within a
        plane; the modes are kept in-plane first, each plane by mode number.
    """

    test: Test
    modes: np.ndarray
    frequencies: np.ndarray
    uncertainty: np.ndarray
    source: str
    damping: np.ndarray | None = None
    damping_uncertainty: np.ndarray | None = None
    damping_is_data: bool | None = None
    planes: np.ndarray | None = None

    def __post_init__(self):
        where = f"test[{self.test.name}]"
        modes = np.asarray(self.modes, int)
        freqs = np.asarray(self.frequencies, float)
        unc = np.broadcast_to(np.asarray(self.uncertainty, float), freqs.shape).copy()
        if modes.ndim != 1 or modes.shape != freqs.shape or modes.size == 0:
            raise InputError("modes and frequencies must be non-empty lists of one length", field=f"{where}.modes")
        planes = np.array(["in"] * modes.size if self.planes is None else list(self.planes), dtype="<U3")
        if planes.shape != modes.shape:
            raise InputError(f"has {planes.size} entries but modes has {modes.size}", field=f"{where}.planes")
        for p in planes:
            if p not in PLANES:
                raise InputError(f'must be "in" or "out", got {str(p)!r}', field=f"{where}.planes")
        if np.any(modes < 1) or len(set(zip(planes.tolist(), modes.tolist()))) != modes.size:
            raise InputError("mode numbers must be distinct integers >= 1" + (" within each plane" if "out" in planes
                                                                               else ""), field=f"{where}.modes")
        if not np.all(np.isfinite(freqs) & (freqs > 0)):
            raise InputError("must be finite and > 0", field=f"{where}.frequencies")
        if not np.all(np.isfinite(unc) & (unc > 0)):
            raise InputError("frequency uncertainties must be finite and > 0", field=f"{where}.uncertainty")
        order = np.lexsort((modes, planes == "out"))
        object.__setattr__(self, "planes", planes[order])
        object.__setattr__(self, "modes", modes[order])
        object.__setattr__(self, "frequencies", freqs[order])
        object.__setattr__(self, "uncertainty", unc[order])
        if (self.damping is None) != (self.damping_uncertainty is None):
            raise InputError("damping ratios need their uncertainties", field=f"{where}.damping")
        if self.damping is not None:
            zeta = np.broadcast_to(np.asarray(self.damping, float), freqs.shape)[order]
            zeta_unc = np.broadcast_to(np.asarray(self.damping_uncertainty, float), freqs.shape)[order]
            object.__setattr__(self, "damping", zeta)
            object.__setattr__(self, "damping_uncertainty", zeta_unc)

    @property
    def damping_used(self) -> np.ndarray:
        """Which modes have a usable damping ratio (finite, with a finite σ > 0)."""
        if self.damping is None:
            return np.zeros(self.modes.size, bool)
        with np.errstate(invalid="ignore"):
            return np.isfinite(self.damping) & np.isfinite(self.damping_uncertainty) & (self.damping_uncertainty > 0)

    @property
    def name(self) -> str:
        return self.test.name

    def labels(self) -> list[str]:
        """A name per mode: ``mode 3`` in-plane, ``mode 3 out-of-plane``."""
        return [mode_label(int(k), str(p)) for k, p in zip(self.modes, self.planes)]

    def subset(self, keep: np.ndarray) -> Measurement:
        """The measurement of the modes where ``keep`` (a mask by mode) is True."""
        keep = np.asarray(keep, bool)
        damping = None if self.damping is None else (self.damping[keep], self.damping_uncertainty[keep])
        return Measurement(self.test, self.modes[keep], self.frequencies[keep], self.uncertainty[keep], self.source,
                           None if damping is None else damping[0], None if damping is None else damping[1],
                           self.damping_is_data, self.planes[keep])


def mode_label(mode: int, plane: str = "in") -> str:
    """``mode 3`` (in-plane) or ``mode 3 out-of-plane``."""
    return f"mode {mode}" + ("" if plane == "in" else f" {PLANE_NAMES[plane]}")


def printed_step(values: Sequence[float]) -> float:
    """Resolution a list of numbers was printed with: 0.01 for (7.24, 44.4)."""
    decimals = 0
    for v in values:
        text = repr(float(v))
        if "e" in text or "E" in text:
            mantissa, exponent = text.lower().split("e")
            digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
            decimals = max(decimals, digits - int(exponent))
        elif "." in text:
            decimals = max(decimals, len(text.split(".")[1].rstrip("0")))
    return 10.0 ** (-decimals)


def table_measurement(test: Test) -> Measurement:
    """A test's tabulated frequencies, with their stated uncertainty (``test.uncertainty``), else the
    rounding of the table as uncertainty (and the source says which)."""
    if test.uncertainty is not None:
        return Measurement(test, np.array(test.modes), np.array(test.frequencies), np.array(test.uncertainty),
                           "stated uncertainty", planes=test.planes)
    step = printed_step(test.frequencies)
    return Measurement(test, np.array(test.modes), np.array(test.frequencies), step / math.sqrt(12),
                       f"table rounding ({step:g} Hz / sqrt 12)", planes=test.planes)


def as_measurement(test: Test, picked) -> Measurement:
    """A :class:`Measurement` from picked spectra (anything with ``modes``,
    ``frequencies`` and ``uncertainty``, as :class:`~stcs_ident.spectra.pipeline.TestSpectra`; the plane of
    each mode from its ``mode_planes``, else ``planes``, else all in-plane)."""
    if isinstance(picked, Measurement):
        return picked
    modes = getattr(picked, "modes", None)
    freqs = getattr(picked, "frequencies", None)
    unc = getattr(picked, "uncertainty", None)
    if modes is None or freqs is None or unc is None:
        raise InputError("picked frequencies need modes, frequencies and uncertainty", field=f"test[{test.name}]")
    if len(modes) == 0:
        raise InputError("no mode was picked from the record", field=f"test[{test.name}].record")
    zeta, zeta_unc = getattr(picked, "damping", None), getattr(picked, "damping_uncertainty", None)
    if zeta is None or zeta_unc is None:
        zeta = zeta_unc = None
    return Measurement(test, np.array(modes), np.array(freqs), np.array(unc), "spectra",
                       None if zeta is None else np.array(zeta, float), None if zeta is None else np.array(zeta_unc, float),
                       planes=picked_planes(picked))


def picked_planes(picked) -> tuple[str, ...] | None:
    """The plane of each picked mode: ``mode_planes`` (:class:`~stcs_ident.spectra.pipeline.TestSpectra`), else
    ``planes``, else None (all in-plane)."""
    for key in ("mode_planes", "planes"):
        value = getattr(picked, key, None)
        if value is not None:
            return tuple(value)
    return None


def without_doubtful(campaign: Campaign, picked: Mapping[str, object] | None) -> tuple[dict, list[Note]]:
    """Picked spectra without the modes whose number the numbering calls doubtful, and a note per test that lost
    some.

    A doubtful number is one that another family of modes, at another tension, gives the peaks almost as well
    (:mod:`~stcs_ident.spectra.numbering`): fitted, a wrong one passes for a tension tens of percent off with a
    small σ, or for a model error. A test keeps its sure modes (with their planes and damping ratios); one with
    none left maps to None, which :func:`gather_measurements` skips, or refuses when the test was named.
    """
    out, notes = {}, []
    known = {t.name for t in campaign.tests}
    for name, spectra in (picked or {}).items():
        flags = getattr(spectra, "doubtful", None)
        doubtful = np.asarray(() if flags is None else flags, bool)
        if name not in known or not doubtful.any() or doubtful.size != len(spectra.modes):
            out[name] = spectra
            continue
        keep = ~doubtful
        planes = picked_planes(spectra) or ("in",) * len(spectra.modes)
        labels = np.array([mode_label(int(k), str(p))[5:] for k, p in zip(spectra.modes, planes)])
        if keep.any():
            zeta, zeta_unc = getattr(spectra, "damping", None), getattr(spectra, "damping_uncertainty", None)
            if zeta is None or zeta_unc is None:
                zeta = zeta_unc = None
            out[name] = Measurement(
                campaign.test(name), np.asarray(spectra.modes)[keep], np.asarray(spectra.frequencies)[keep],
                np.asarray(spectra.uncertainty)[keep], "spectra",
                None if zeta is None else np.asarray(zeta, float)[keep],
                None if zeta is None else np.asarray(zeta_unc, float)[keep], planes=np.asarray(planes)[keep])
            notes.append(Note.make("doubtful_modes", "{test}: modes {modes} left out (their numbers are doubtful)",
                                   test=name, modes=", ".join(labels[doubtful])))
        else:
            out[name] = None
            notes.append(Note.make("doubtful_modes", "{test}: every mode left out (modes {modes}: their numbers "
                                   "are doubtful)", test=name, modes=", ".join(labels)))
    return out, notes


def with_record_spectra(campaign: Campaign, tests: Sequence[str] | None,
                        picked: Mapping[str, object] | None) -> dict:
    """``picked`` with the spectra of every selected test measured by its record alone computed (as
    :func:`gather_measurements` would compute them), so that the records can be judged before their numbers are
    used (:func:`~stcs_ident.identify.plausibility.check_records`). Unknown names are left to
    :func:`gather_measurements` to refuse."""
    out = dict(picked or {})
    known = {t.name for t in campaign.tests}
    names = [n for n in tests if n in known] if tests else sorted(known, key=[t.name for t in campaign.tests].index)
    for name in names:
        test = campaign.test(name)
        if name not in out and test.frequencies is None and test.record is not None:
            from ..spectra.pipeline import analyse_test  # lazily: reads the record

            out[name] = analyse_test(campaign, test)
    return out


def gather_measurements(campaign: Campaign, tests: Sequence[str] | None = None,
                        picked: Mapping[str, object] | None = None,
                        notes: list[Note] | None = None) -> tuple[list[Measurement], list[tuple[str, str]]]:
    """The measurements of the selected tests, and the tests skipped with why.

    A test is measured by ``picked[name]`` when given (spectra or a
    :class:`Measurement`), else by its table of frequencies, else by the
    spectra of its record (computed here). A test with none of these, or
    whose ``picked[name]`` is None (every number doubtful:
    :func:`without_doubtful`), is skipped when all tests are used, and is
    an error when it was selected by name. The spectra computed here lose
    their doubtful modes too, with a note appended to ``notes`` (when given).

    Raises
    ------
    InputError
        For a test name that does not exist, a selected test without
        frequencies or record, or when no test is left.
    """
    picked = dict(picked or {})
    known = [t.name for t in campaign.tests]
    for name in list(tests or []) + list(picked):
        if name not in known:
            raise InputError(f"no test named {name!r} (known: {', '.join(known)})", field="test")
    selected = [campaign.test(n) for n in tests] if tests else list(campaign.tests)
    out, skipped = [], []
    for test in selected:
        if test.name not in picked and test.frequencies is None and test.record is not None:
            from ..spectra.pipeline import analyse_test  # lazily: reads the record

            sure, lost = without_doubtful(campaign, {test.name: analyse_test(campaign, test)})
            picked.update(sure)
            if notes is not None:
                notes.extend(lost)
        if test.name in picked and picked[test.name] is None:  # every number doubtful (:func:`without_doubtful`)
            if tests:
                raise InputError("the mode number of every peak picked from it is doubtful (another family of "
                                 "modes, at another tension, fits them almost as well): nothing sure to identify "
                                 "from", field=f"test[{test.name}].record")
            skipped.append((test.name, "every picked mode's number is doubtful"))
        elif test.name in picked:
            out.append(as_measurement(test, picked[test.name]))
        elif test.frequencies is not None:
            out.append(table_measurement(test))
        elif tests:
            raise InputError("has neither measured frequencies nor a record: nothing to identify from",
                             field=f"test[{test.name}].frequencies")
        else:
            skipped.append((test.name, "no measured frequencies and no record"))
    if not out:
        if not skipped:
            raise InputError("the campaign has no test to identify from", field="test")
        name = skipped[0][0]
        where = "record" if campaign.test(name).record is not None else "frequencies"
        reasons = "; ".join(f"{n}: {r}" for n, r in skipped)
        raise InputError(f"no test is left to identify from ({reasons})", field=f"test[{name}].{where}")
    return out, skipped
