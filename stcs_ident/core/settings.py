"""The settings of a run, in one frozen object that every result records.

A result says how it was made (``result.settings``), so that whatever
renders or extends it (the diagnosis report's nominal comparison, say)
reads the settings from the result instead of being told them again.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from .errors import InputError

#: How the additional tension from sag-extensibility is modelled: one for the whole cable (as horizontal
#: equilibrium requires), one per segment (the source paper's Eq. 6), or none.
TENSION_MODELS = ("uniform", "per-segment", "none")

#: When the covariance is scaled by the reduced χ² (see :func:`stcs_ident.identify.uncertainty.covariance_scale`).
SCALE_RULES = ("auto", "birge", "never")


@dataclass(frozen=True)
class Settings:
    """How a step was run; validated when built (the error names the field).

    A step records the settings it ran with; the fields it does not use
    keep their defaults.

    Attributes
    ----------
    tension_model : {"uniform", "per-segment", "none"}
        Additional tension from sag-extensibility in the forward model
        (every step).
    scale_rule : {"auto", "birge", "never"}
        When the covariance of an identification is scaled by the reduced
        χ² (identification, and the fits of a diagnosis).
    max_effects : {1, 2}
        Largest number of effects combined in one hypothesis (diagnosis).
    all_hypotheses : bool
        Whether every pair of effects is fitted even when the nominal model
        explains the data (diagnosis).
    """

    tension_model: str = "uniform"
    scale_rule: str = "auto"
    max_effects: int = 2
    all_hypotheses: bool = False

    def __post_init__(self):
        if self.tension_model not in TENSION_MODELS:
            raise InputError(f"must be one of {', '.join(TENSION_MODELS)}, got {self.tension_model!r}",
                             field="tension_model")
        if self.scale_rule not in SCALE_RULES:
            raise InputError(f"must be one of {', '.join(SCALE_RULES)}, got {self.scale_rule!r}", field="scale_rule")
        if isinstance(self.max_effects, bool) or self.max_effects not in (1, 2):
            raise InputError(f"must be 1 or 2, got {self.max_effects!r}", field="max_effects")
        if not isinstance(self.all_hypotheses, bool):
            raise InputError(f"must be true or false, got {self.all_hypotheses!r}", field="all_hypotheses")

    def summary(self) -> dict:
        """Plain data for JSON."""
        return asdict(self)
