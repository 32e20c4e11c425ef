"""Diagnosis: show what the model gets wrong, name the cause, extend the model, measure the gain."""

from .api import diagnose
from .hypotheses import EFFECTS
from .result import Diagnosis

__all__ = ["EFFECTS", "Diagnosis", "diagnose"]
