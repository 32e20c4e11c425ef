"""Identification: correct uncertain model parameters from measured frequencies.

- :func:`identify`: the entry point (``method="lsq"`` or ``"contour"``);
- :func:`parse_parameters` and :class:`Parameter`: the free parameters
  (tension per test; EI, length, end stiffness, attachment position, mass
  and spring), reused by the diagnosis step;
- :class:`Problem` and :class:`Measurement`: measured data and the model,
  evaluated in batches;
- :func:`fit_lsq`, :func:`fit_contour`: the two methods on a built problem;
- :class:`IdentificationResult`, :class:`TestFit`: results, with
  ``.summary()`` (JSON) and ``.to_dataframe()`` (the paper's Table 9/10
  form); :mod:`.tables` lays them out as text, Markdown and CSV;
- :func:`corrected_campaign`: the campaign with the estimates in place of the
  nominal values (to chain identifications, as the paper does);
- :class:`IdentifiabilityWarning`.
"""

from __future__ import annotations

import importlib

#: Every name of the subpackage and the module it comes from, imported when first used (PEP 562): the quick
#: tension (:mod:`.quick`) then loads neither the contour method nor pandas (``stcs-ident tension`` in 0.3 s
#: rather than 1.5 s).
_EXPORTS = {
    "Parameter": "..core.parameters", "parse_parameters": "..core.parameters", "METHODS": ".api",
    "identify": ".api", "ContourSweep": ".contour", "fit_contour": ".contour", "corrected_campaign": ".corrected",
    "fit_lsq": ".lsq", "Measurement": ".problem", "Problem": ".problem", "gather_measurements": ".problem",
    "IdentificationResult": ".result", "TestFit": ".result", "IdentifiabilityWarning": ".uncertainty",
}

__all__ = [
    "METHODS", "ContourSweep", "IdentifiabilityWarning", "IdentificationResult", "Measurement", "Parameter",
    "Problem", "TestFit", "corrected_campaign", "fit_contour", "fit_lsq", "gather_measurements", "identify",
    "parse_parameters",
]


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_EXPORTS[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + list(_EXPORTS))
