"""The second resonances found in numbered modes' bands (:mod:`.two_poles`), reported as structural.

A deck's mode a per cent from a cable mode, in a record without axial channels, is rarely a peak of its own: it
shapes the cable mode's peak, whose one-pole fit then misfits its band, and the likelihood-ratio test of
:mod:`.two_poles` finds it as a second pole. The numbered mode keeps its one-pole fit (its 1σ widened where its
fit misfits: :mod:`.plane_analysis`); the second pole is reported in ``structural`` with its evidence, never
numbered, unless it lies within the 3σ of a peak reported already (a numbered mode of either plane, an unassigned
or a structural peak): the other plane's mode leaking through a turned sensor, or a resonance picked apart. One
that lies where a mode of the plane's family that is not numbered is expected (a heavily damped cable's next mode
in a wide band) is reported as unassigned, not as structural: the pole alone cannot tell them apart.
Used by :mod:`.pipeline` on every record's :class:`~.pipeline.TestSpectra` (not imported here, which would close
a circle).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.notes import Note
from ..core.planes import PLANE_NAMES

__all__ = ["MISFIT_QUESTION", "with_second_resonances"]

#: The end of a ``misfit`` note (:mod:`.pipeline`), the question a second resonance found in the band answers.
MISFIT_QUESTION = " (a resonance merged with it?)"


def with_second_resonances(spectra):
    """``spectra`` with the second poles of its numbered modes' bands in ``structural`` (module docstring), each
    said in its mode's note (:func:`_merged_notes`); unchanged where there are none."""
    planes = spectra.planes is not None
    results = dict(spectra.plane_peaks) if planes else {"in": spectra.peaks}
    reported = [(float(f), float(u)) for f, u in zip(spectra.frequencies, spectra.uncertainty)]
    reported += [(float(f), float(u)) for f, u in spectra.unassigned]
    reported += [(float(f), float(u)) for f, u, _ in spectra.structural]
    found = []
    for mode, plane, f in zip(spectra.modes, spectra.mode_planes, spectra.frequencies):
        peak = next((p for p in results[plane].peaks if p.frequency == f), None)
        if peak is not None and peak.second_pole is not None:
            found.append((peak.second_pole, mode, plane, float(f)))
    added, cable_like, notes = [], [], {}
    for (f2, u2, statistic), mode, plane, own in sorted(found, key=lambda item: -item[0][2]):
        if any(abs(f2 - f) <= 3.0 * u for f, u in reported if f != own):  # a peak reported already: within its 3σ
            continue
        name = f"{PLANE_NAMES[plane]} mode {mode}" if planes else f"mode {mode}"
        evidence = f"2Δℓ = {statistic:.0f}, two poles against one"
        missing = _expected_missing(spectra, plane, f2, u2)
        reported.append((f2, u2))
        what = f"a second resonance at {f2:.4f} ± {u2:.2g} Hz in its band ({evidence})"
        if missing is not None:  # where a mode of the plane's family not numbered is expected: not told apart
            cable_like.append((float(f2), float(u2), plane))
            notes[name] = f"{what}, where mode {missing} is expected: unassigned"
            continue
        added.append((float(f2), float(u2), f"a second pole in {name}'s band ({evidence})"))
        notes[name] = f"{what}: structural"
    if not notes:
        return spectra
    structural = tuple(sorted(spectra.structural + tuple(added), key=lambda s: s[0]))
    unassigned = spectra.unassigned + tuple((f, u) for f, u, _ in cable_like)
    unassigned_planes = spectra.unassigned_planes
    if planes and cable_like:
        unassigned_planes = tuple(unassigned_planes or ()) + tuple(plane for _, _, plane in cable_like)
    return replace(spectra, structural=structural, unassigned=unassigned, unassigned_planes=unassigned_planes,
                   plane_notes=_merged_notes(spectra.plane_notes, notes))


def _merged_notes(plane_notes: tuple, found: dict) -> tuple:
    """``plane_notes`` with each mode's second resonance said once: in the mode's ``misfit`` note where it has one
    (its fit misfits its band: this is what it holds), else in a note of its own (kind ``second_resonance``)."""
    out, said = [], set()
    for note in plane_notes:
        name = next((n for n in found if note.kind == "misfit" and str(note).startswith(f"{n}: ")), None)
        if name is None:
            out.append(note)
            continue
        out.append(Note.plain("second_resonance", f"{str(note).replace(MISFIT_QUESTION, '')}: {found[name]}"))
        said.add(name)
    out += [Note.plain("second_resonance", f"{name}: {text}") for name, text in found.items() if name not in said]
    return tuple(out)


def _expected_missing(spectra, plane: str, frequency: float, uncertainty: float) -> int | None:
    """The number of a mode of ``plane`` not numbered in ``spectra`` whose frequency, expected from the plane's
    nominal family scaled by the numbered modes' ratios to it (interpolated between them: the ratios are nearly
    one, a tension's square root, along a family), lies within 3σ of ``frequency`` (σ: ``uncertainty`` and the
    ratios' scatter); None where there is none or the plane has no nominal family."""
    nominal = dict(spectra.plane_nominal).get(plane) if spectra.plane_nominal else spectra.nominal_frequencies
    own = sorted((m, float(f)) for m, p, f in zip(spectra.modes, spectra.mode_planes, spectra.frequencies)
                 if p == plane and m <= len(nominal if nominal is not None else ()))
    if nominal is None or not own:
        return None
    numbers = np.array([m for m, _ in own], float)
    ratios = np.array([f / nominal[m - 1] for m, f in own])
    scatter = float(np.std(ratios)) if ratios.size > 1 else 0.02
    for k in range(1, len(nominal) + 1):
        if k in numbers:
            continue
        expected = nominal[k - 1] * float(np.interp(k, numbers, ratios))
        if abs(frequency - expected) <= 3.0 * np.hypot(uncertainty, scatter * nominal[k - 1]):
            return k
    return None
