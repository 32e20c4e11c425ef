"""Diagnosis: show what the model gets wrong, name the cause, extend the model, measure the gain."""

from .api import diagnose
from .result import Diagnosis

__all__ = ["Diagnosis", "diagnose"]
