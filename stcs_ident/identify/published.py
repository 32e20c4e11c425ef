"""Identified values beside results published elsewhere (``[[published]]``)."""

from __future__ import annotations

from ..core.formatting import plus_minus
from ..core.model import Campaign

#: Nominal value of each ratio parameter, from the campaign's cable.
_NOMINAL = {"EI_ratio": lambda c: c.cable.EI, "length_ratio": lambda c: c.cable.length}
#: Unit of that nominal value.
_UNIT = {"EI_ratio": "N m^2", "length_ratio": "m"}


def published_comparison(campaign: Campaign, summary: dict) -> list[dict]:
    """One entry per published result whose parameter was identified.

    Parameters
    ----------
    campaign : Campaign
    summary : dict
        ``IdentificationResult.summary()``.

    Returns
    -------
    list of dict with the published range, ours with its 1σ, both in the
    published basis and in the nominal, the difference in σ, and a sentence.
    """
    out = []
    for item in campaign.published:
        ours = summary.get("parameters", {}).get(item.parameter)
        sigma = summary.get("uncertainty", {}).get(item.parameter)
        if ours is None or isinstance(ours, dict) or sigma is None:
            continue
        nominal = _NOMINAL[item.parameter](campaign) if item.parameter in _NOMINAL else None
        basis = item.basis if item.basis is not None else nominal
        # express ours in the published basis (a ratio to `basis`)
        scale = nominal / basis if (nominal is not None and basis is not None) else 1.0
        ours_b, sigma_b = ours * scale, sigma * scale
        mid = 0.5 * (item.low + item.high)
        distance = 0.0 if item.low <= ours_b <= item.high else min(abs(ours_b - item.low), abs(ours_b - item.high))
        n_sigma = distance / sigma_b if sigma_b > 0 else float("inf")
        text = f"{item.parameter}: published {item.low:g}–{item.high:g}"
        if item.basis is not None:
            text += f" of {item.basis:.4g}"
            if nominal is not None:
                text += (f" (= {item.low * item.basis:.4g}–{item.high * item.basis:.4g}, i.e. "
                         f"{item.low / scale:.3f}–{item.high / scale:.3f} of the nominal {nominal:.4g})")
        text += f" [{item.source}]" if item.source else ""
        text += f"; this identification: {plus_minus(ours, sigma)} of the nominal"
        if nominal is not None:
            text += f" (= {plus_minus(ours * nominal, sigma * nominal, _UNIT.get(item.parameter, ''))})"
        if item.basis is not None:
            text += f", i.e. {plus_minus(ours_b, sigma_b)} of {item.basis:.4g}"
        text += (", consistent with it." if n_sigma <= 1 else
                 f", {n_sigma:.1f} σ outside the published range.")
        out.append({"parameter": item.parameter, "published": [item.low, item.high], "basis": item.basis,
                    "source": item.source, "identified_in_basis": ours_b, "uncertainty_in_basis": sigma_b,
                    "published_mid": mid, "sigma_outside": n_sigma, "statement": text})
    return out
