"""Numbered modes made doubtful after the numbering, by what their fits and shapes say: an operating shape far
from its number's (:func:`low_mac_doubtful`) and a peak wider than its family's mode spacing (:func:`blends_doubtful`).
Used by :mod:`.pipeline` on every record's :class:`~.pipeline.TestSpectra` (each function takes one and
returns it, replaced where something changed; not imported here, which would close a circle).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.notes import Note
from ..core.planes import PLANE_NAMES

__all__ = ["BLEND_SPACINGS", "FAMILY_MAC", "LOW_MAC", "blends_doubtful", "low_mac_doubtful"]

#: A numbered mode whose MAC is below this while its plane's family's median MAC is at least
#: :data:`FAMILY_MAC` is doubtful: its operating shape is not the mode its number names (measured on the slips of
#: issue 34: a tension typed in kN numbered peaks 10, 18, 21 at MAC 0.48, 0.04, 0.00; a correct campaign's modes
#: are at 0.95-1.00 wherever the sensors can tell the shapes apart).
LOW_MAC, FAMILY_MAC = 0.3, 0.8


def low_mac_doubtful(spectra):
    """``spectra`` with the numbered modes whose MAC is far below their plane's family's own made doubtful
    (:data:`LOW_MAC`), with a note naming them."""
    if spectra.mac is None or not len(spectra.modes):
        return spectra
    macs = np.asarray(spectra.mac, float)
    planes = np.asarray(spectra.mode_planes)
    low = np.zeros(macs.size, bool)
    for plane in set(planes.tolist()):
        own = (planes == plane) & np.isfinite(macs)
        if own.sum() >= 3 and np.median(macs[own]) >= FAMILY_MAC:
            low |= own & (macs < LOW_MAC)
    low &= ~np.asarray(spectra.doubtful, bool)
    if not low.any():
        return spectra
    names = ", ".join(f"{PLANE_NAMES[p] + ' ' if spectra.planes is not None else ''}mode {m} (MAC {a:.2f})"
                      for m, p, a in zip(np.asarray(spectra.modes)[low], planes[low], macs[low]))
    note = Note.plain("low_mac", f"{names}: operating shape far from the model's (the family's median MAC is "
                                 f"{FAMILY_MAC:g} or more): number doubtful")
    return replace(spectra, doubtful=tuple(bool(d) for d in np.asarray(spectra.doubtful, bool) | low),
                   plane_notes=spectra.plane_notes + (note,))


#: A numbered mode whose fitted half-power width (2ζf) is this many of its family's mode spacings or more is a
#: blend: one pole fitted where the band holds several of the family's modes (a heavily damped stay's high modes,
#: or a fit across two of them), its frequency between theirs and its ζ theirs plus their spacing. Measured on
#: benchmarks/short_records.py's stays (seed 36000, 30-120 s, ζ 0.2-2 %): of 716 numbered modes narrower than
#: one spacing, 99 % within 3σ and 8 off by more than max(3σ, 0.5 %); of 18 at 1.5 spacings or more, 61 % and 7
#: off, 3 of them sure (the 4 between 1 and 1.5 spacings: within 3σ).
BLEND_SPACINGS = 1.0


def blends_doubtful(spectra):
    """``spectra`` with its blends (:data:`BLEND_SPACINGS`) made doubtful, their 1σ at least their half-power
    half-width (ζf: where one pole stands for several, the frequency is known to no better than its width) and
    their damping ratio not reported (it is the blend's), with a note naming them."""
    if not len(spectra.modes):
        return spectra
    nominal = dict(spectra.plane_nominal) or {"in": spectra.nominal_frequencies}
    frequencies = np.asarray(spectra.frequencies, float)
    half_width = np.asarray(spectra.damping, float) * frequencies  # ζf, NaN where no damping ratio
    spacing = np.full(len(spectra.modes), np.nan)
    for k, (mode, plane) in enumerate(zip(spectra.modes, spectra.mode_planes)):
        family = nominal.get(plane)
        if family is None or mode > len(family) or len(family) < 2:
            continue
        neighbours = np.asarray(family, float)[[j for j in (mode - 2, mode) if 0 <= j < len(family)]]
        own = float(family[mode - 1])
        spacing[k] = np.mean(np.abs(neighbours - own)) * frequencies[k] / own  # the family's, at the measured mode
    with np.errstate(invalid="ignore"):
        blend = 2.0 * half_width >= BLEND_SPACINGS * spacing  # False where either is NaN
    if not blend.any():
        return spectra
    unc = np.where(blend, np.maximum(spectra.uncertainty, half_width), spectra.uncertainty)
    damping = np.where(blend, np.nan, spectra.damping)
    damping_unc = spectra.damping_uncertainty
    if damping_unc is not None:
        damping_unc = np.where(blend, np.nan, damping_unc)
    planes = spectra.planes is not None
    names = ", ".join(f"{PLANE_NAMES[p] + ' ' if planes else ''}mode {m} (half-power width {2 * h:.3g} Hz, "
                      f"spacing {d:.3g} Hz)" for m, p, h, d, b in
                      zip(spectra.modes, spectra.mode_planes, half_width, spacing, blend) if b)
    note = Note.plain("blend", f"{names}: one pole wider than its family's mode spacing, a blend of several modes: "
                               "number doubtful, 1σ widened to its half-power half-width, no damping ratio")
    return replace(spectra, doubtful=tuple(bool(d) for d in np.asarray(spectra.doubtful, bool) | blend),
                   uncertainty=unc, damping=damping, damping_uncertainty=damping_unc,
                   plane_notes=spectra.plane_notes + (note,))
