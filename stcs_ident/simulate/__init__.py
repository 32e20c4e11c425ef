"""Simulation: acceleration records and whole campaigns from a true cable model.

The simulator builds on the forward model and writes records of the type
:mod:`stcs_ident.spectra` reads; spectra never imports it.
"""

from .bridge import BridgeConditions, StructuralMode, Traffic
from .conditions import (
    DcOffsets,
    FieldConditions,
    LowPassLoading,
    MainsHum,
    PinkNoise,
    RecordTruth,
    TensionDrift,
    random_field_conditions,
)
from .effects import Effects, true_model
from .simulate import (
    NYQUIST_FRACTION,
    UNCORRELATED_LENGTH,
    Ambient,
    Impulse,
    modal_basis,
    modal_damping,
    simulate_record,
    simulate_record_with_truth,
)
from .simulate_campaign import TRUTH_FILE, simulate_campaign

__all__ = [
    "NYQUIST_FRACTION", "TRUTH_FILE", "UNCORRELATED_LENGTH", "Ambient", "BridgeConditions", "DcOffsets", "Effects",
    "FieldConditions", "Impulse", "LowPassLoading", "MainsHum", "PinkNoise", "RecordTruth", "StructuralMode",
    "TensionDrift", "Traffic", "modal_basis",
    "modal_damping", "random_field_conditions", "simulate_campaign", "simulate_record", "simulate_record_with_truth",
    "true_model",
]
