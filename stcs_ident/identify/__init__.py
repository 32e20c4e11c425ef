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

from ..core.parameters import Parameter, parse_parameters
from .api import METHODS, identify
from .contour import ContourSweep, fit_contour
from .corrected import corrected_campaign
from .lsq import fit_lsq
from .problem import Measurement, Problem, gather_measurements
from .result import IdentificationResult, TestFit
from .uncertainty import IdentifiabilityWarning

__all__ = [
    "METHODS", "ContourSweep", "IdentifiabilityWarning", "IdentificationResult", "Measurement", "Parameter",
    "Problem", "TestFit", "corrected_campaign", "fit_contour", "fit_lsq", "gather_measurements", "identify",
    "parse_parameters",
]
