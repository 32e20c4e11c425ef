"""Plausibility of a campaign before any fit: does the nominal model come near what was measured?

A fit started from a nominal model that is off by a unit slip (tensions
entered in kN, a mass per length in g/m) does not fail: it stops at a bound
or finds a tension ratio of 1.9 and an EI eight times the nominal one, and
says nothing. Before any fit, :func:`check_plausibility` compares, for
every measured test, the nominal model's frequency of the lowest measured
mode with the measured one. Outside ×/÷ :data:`BAND` the campaign is
refused (:class:`~stcs_ident.core.errors.InputError`, exit 2 from the
command line) with the field and the likely slip, computed from the ratio
(:func:`likely_slips`: each slip of :data:`TENSION_SLIPS` and
:data:`MASS_SLIPS` undone in the model, kept when that brings the test
within the band). A user who means it passes
``check_plausibility=False`` (``--no-plausibility-check``).

:func:`implausible` gives the same findings without refusing (``forward``
prints them as a warning line).

On the record path the measured modes are numbered against the nominal
family, which a slip has already bent: :func:`check_records` judges each
record instead by its peaks' own harmonic series
(:mod:`stcs_ident.spectra.scale_check`), before the numbers are used, and
names a sampling rate typed a round factor off as well as the unit slips.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..core.errors import InputError
from ..core.model import Campaign
from ..forward import batch_frequencies
from ..io.test_record import record_reading
from ..spectra.scale_check import SCALE_BAND, round_factor
from .problem import Measurement

#: Largest plausible ratio (either way) of the nominal to the measured frequency of the lowest measured mode.
#: A correct campaign's stated tension is within tens of per cent of the truth, and f ∝ √T gives a ratio
#: within 1.3 for a true tension 0.6–1.7 × the stated one (more than a hidden mass or an end restraint
#: moves the lowest mode); a unit slip is a factor √1000 ≈ 31.6 or more.
BAND = SCALE_BAND
#: Tension factor (true / stated) of a unit slip in a test's ``tension`` (N): the hint it gives.
TENSION_SLIPS = {1e3: "kN", 1e6: "MN", 9.80665e3: "tonnes-force", 9.80665: "kgf", 1e-3: "mN, or N where kN was meant"}
#: Mass factor (true / stated) of a unit slip in ``cable.mass_per_length`` (kg/m): the hint it gives.
MASS_SLIPS = {1e-3: "g/m", 1e3: "t/m", 1 / 9.80665: "N/m (a weight per length)"}


@dataclass(frozen=True)
class Finding:
    """One test whose nominal model is far from its measurement.

    Attributes
    ----------
    test : str
    mode : int
        The lowest measured mode.
    nominal, measured : float
        Its nominal and measured frequencies (Hz).
    tension : float
        The test's stated tension (N).
    """

    test: str
    mode: int
    nominal: float
    measured: float
    tension: float

    @property
    def ratio(self) -> float:
        """nominal / measured."""
        return self.nominal / self.measured

    def sentence(self) -> str:
        """``tension 1248.7 N: nominal f1 0.23 Hz is 31.6× below the measured 7.24 Hz``."""
        r = self.ratio
        word = f"{1 / r:.3g}× below" if r < 1 else f"{r:.3g}× above"
        return (f"tension {self.tension:.6g} N: nominal f{self.mode} {self.nominal:.3g} Hz is {word} the measured "
                f"{self.measured:.4g} Hz")


def _nominal(campaign: Campaign, m: Measurement, mode: int, tension_model: str, tension: float | None = None,
             cable=None) -> float:
    """The nominal model's frequency of ``mode`` for the test of ``m`` (Hz), optionally with another tension
    or cable; in the plane of the first measured ``mode`` (in-plane first, as :func:`_lowest` picks it)."""
    atts = campaign.setup(m.test.setup).attachments
    plane = str(m.planes[m.modes == mode][0]) if np.any(m.modes == mode) else "in"
    f = batch_frequencies(cable or campaign.cable, atts, m.test.tension if tension is None else tension, mode,
                          tension_model=tension_model, plane=plane)
    return float(np.asarray(f).ravel()[mode - 1])


def _lowest(m: Measurement) -> tuple[int, float]:
    i = int(np.argmin(m.modes))
    return int(m.modes[i]), float(m.frequencies[i])


def _within(nominal: float, measured: float, band: float) -> bool:
    return math.isfinite(nominal) and nominal > 0 and 1 / band <= nominal / measured <= band


def implausible(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str = "uniform",
                band: float = BAND) -> list[Finding]:
    """The measured tests whose nominal frequency of the lowest measured mode is outside ×/÷ ``band`` of
    the measured one (tests in order; empty when all are plausible)."""
    out = []
    for m in measurements:
        if m.modes.size == 0:
            continue
        mode, measured = _lowest(m)
        nominal = _nominal(campaign, m, mode, tension_model)
        if measured > 0 and math.isfinite(nominal) and not _within(nominal, measured, band):
            out.append(Finding(m.test.name, mode, nominal, measured, float(m.test.tension)))
    return out


def likely_slips(campaign: Campaign, measurements: Sequence[Measurement], findings: Sequence[Finding],
                 tension_model: str = "uniform") -> tuple[list[str], list[str]]:
    """(tension slips, mass slips): the unit slip of :data:`TENSION_SLIPS` that, undone in every test of
    ``findings``, brings each within the band best, and the slip of :data:`MASS_SLIPS` that, undone in the
    cable, brings every measured test within it best (only when every measured test is off); each list
    holds one slip at most. Recomputed with the model, not read off the frequency ratio: on a stiff cable
    at a low tension bending sets the frequency, and a tension 1000 × too low lowers it far less than
    √1000."""
    off = {f.test for f in findings}
    chosen = [m for m in measurements if m.test.name in off]
    measured = [m for m in measurements if m.modes.size]

    def worst(tests, **change) -> float:
        """Largest |log(nominal / measured)| over ``tests`` with the slip undone (inf: outside the band)."""
        out = 0.0
        for m in tests:
            mode, f = _lowest(m)
            tension = m.test.tension * change["k"] if "k" in change else None
            nominal = _nominal(campaign, m, mode, tension_model, tension=tension, cable=change.get("cable"))
            if not _within(nominal, f, BAND):
                return math.inf
            out = max(out, abs(math.log(nominal / f)))
        return out

    def best(scores: dict[str, float]) -> list[str]:
        finite = {w: v for w, v in scores.items() if math.isfinite(v)}
        return [min(finite, key=finite.get)] if finite else []

    tension = best({word: worst(chosen, k=k) for k, word in TENSION_SLIPS.items()})
    mass: dict[str, float] = {}
    if len(off) == len(measured):
        for q, word in MASS_SLIPS.items():
            try:
                cable = replace(campaign.cable, mass_per_length=campaign.cable.mass_per_length * q)
            except ValueError:  # beyond any cable (ModelError): not this slip
                continue
            mass[word] = worst(measured, cable=cable)
    return tension, best(mass)


def hint(findings: Sequence[Finding], n_tests: int, tension_slips: Sequence[str] = (),
         mass_slips: Sequence[str] = ()) -> tuple[str, str]:
    """(field, one-line message) for ``findings`` of ``n_tests`` measured tests and the likely slips."""
    first = max(findings, key=lambda f: abs(math.log(f.ratio)))
    guesses = [f"tension in {w}?" for w in tension_slips] + [f"cable.mass_per_length in {w}?" for w in mass_slips]
    if not guesses:
        guesses.append("check the units and values of the tension, cable.mass_per_length, cable.length and "
                       "cable.EI")
    field = "cable.mass_per_length" if mass_slips and not tension_slips else f"test[{first.test}].tension"
    scope = (f"every measured test is off ({len(findings)} of {n_tests}); " if len(findings) == n_tests > 1 else
             (f"{len(findings)} of {n_tests} measured tests are off; " if len(findings) > 1 else ""))
    message = (f"the nominal model is implausibly far from the measurement ({scope}test {first.test}: "
               f"{first.sentence()}, outside ×/÷ {BAND:g}) — {' or '.join(guesses)}")
    return field, message


def assess(campaign: Campaign, measurements: Sequence[Measurement],
           tension_model: str = "uniform") -> tuple[str, str] | None:
    """(field, message) naming the implausible field and the likely slip, or None when the nominal model is
    within the band of every measured test (what ``forward`` prints as a warning)."""
    findings = implausible(campaign, measurements, tension_model)
    if not findings:
        return None
    slips = likely_slips(campaign, measurements, findings, tension_model)
    return hint(findings, sum(1 for m in measurements if m.modes.size), *slips)


def check_plausibility(campaign: Campaign, measurements: Sequence[Measurement], tension_model: str = "uniform"):
    """Refuse a campaign whose nominal model is implausibly far from its measurements (module docstring).

    Raises
    ------
    InputError
        Naming the field (``test[<name>].tension``; ``cable.mass_per_length`` when only a mass slip
        explains the misfit) and the likely unit slip; the message ends with the override.
    """
    found = assess(campaign, measurements, tension_model)
    if found is not None:
        field, message = found
        raise InputError(f"{message} (if you mean it: --no-plausibility-check)", field=field)


#: How a record path's refusal begins (``track`` recognises a cable whose first records all say it).
IMPLAUSIBLE = "the nominal model is implausibly far from the record"


def record_findings(campaign: Campaign, picked) -> list[tuple[Finding, Measurement, object]]:
    """Per picked test whose peaks' own series is implausibly far from the nominal family (the spectra's
    ``implausible_scale``): the finding, the peaks as the series numbers them, and the check."""
    out = []
    names = {t.name for t in campaign.tests}
    for name, spectra in (picked or {}).items():
        bad = getattr(spectra, "implausible_scale", ())
        if name not in names or not bad:
            continue
        check = max(bad, key=lambda c: abs(math.log(c.ratio)))
        numbered = check.series.modes > 0
        order = np.argsort(check.series.modes[numbered])
        modes = check.series.modes[numbered][order]
        freqs = np.asarray(check.frequencies, float)[numbered][order]
        test = campaign.test(name)
        m = Measurement(test, modes, freqs, np.maximum(1e-3 * freqs, 1e-12), "spectra",
                        planes=np.full(modes.size, check.plane))
        out.append((Finding(name, check.mode, check.nominal, check.measured, float(test.tension)), m, check))
    return out


def check_records(campaign: Campaign, picked, tension_model: str = "uniform") -> None:
    """Refuse a campaign whose records' peaks form a series implausibly far from the nominal model (module
    docstring): the field and the likely slip (a tension or mass unit, a sampling rate a round factor off).

    Raises
    ------
    InputError
        Naming the field (``test[<name>].tension``, ``cable.mass_per_length``, or the sampling rate: the
        test's ``record_format.sampling_rate`` where the campaign gives it, else the record file's) and the
        likely slip; the message ends with the override.
    """
    found = record_findings(campaign, picked)
    if not found:
        return
    findings = [f for f, _, _ in found]
    measurements = [m for _, m, _ in found]
    first, _, check = max(found, key=lambda item: abs(math.log(item[2].ratio)))
    spectra = picked[first.test]
    tension_slips, mass_slips = likely_slips(campaign, measurements, findings, tension_model)
    n_records = sum(1 for name in picked if name in {t.name for t in campaign.tests})
    if len(findings) < n_records:
        mass_slips = []  # a mass slip moves every record
    guesses = [f"tension in {w}?" for w in tension_slips] + [f"cable.mass_per_length in {w}?" for w in mass_slips]
    field, file = (f"test[{first.test}].tension" if tension_slips or not mass_slips else "cable.mass_per_length",
                   None)
    factor = round_factor(check.ratio)
    if factor is not None:
        given = next((g for option, g, _ in getattr(spectra, "record_replaced", ()) if option == "sampling_rate"),
                     None)
        rate = record_reading(campaign, campaign.test(first.test)).options.get("sampling_rate")
        word = f"{factor:g}× too high" if factor > 1 else f"{1 / factor:g}× too low"
        where = (f"test[{first.test}].record_format.sampling_rate ({rate:g} Hz)" if rate is not None else
                 "the record's sampling rate")
        guesses.insert(0, f"{where} {word}?")
        if not tension_slips and not mass_slips:
            field = (f"test[{first.test}].record_format.sampling_rate" if rate is not None or given is not None
                     else "sampling_rate")
            file = None if rate is not None else getattr(spectra, "record", None)
    if not guesses:
        guesses.append("check the units and values of the tension, cable.mass_per_length, cable.length and "
                       "cable.EI, and the record's sampling rate")
    scope = f"{len(findings)} of {n_records} records are off; " if n_records > 1 else ""
    message = (f"{IMPLAUSIBLE} ({scope}test {first.test}: "
               f"{check.sentence()}, outside ×/÷ {BAND:g}) — {' or '.join(guesses)} "
               "(if you mean it: --no-plausibility-check)")
    raise InputError(message, field=field, file=file)
