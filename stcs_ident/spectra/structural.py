"""What is not the cable's: operating shapes against the model's (MAC), the anchorage's motion, harmonics.

A deck's or pylon's mode moves the cable's anchorage; the cable follows at that frequency, and a peak
appears that belongs to none of the cable's families. It is told apart

- by the family fit (:mod:`.numbering` leaves it unassigned);
- by its operating shape: a numbered peak's amplitudes at the sensors of its plane (signed by phase:
  :class:`.peaks.Peak`) are compared with the model's shape of its mode at the same positions by the modal
  assurance criterion MAC = (φᵀa)² / (φᵀφ · aᵀa), 1 for proportional shapes; it is meaningful with two
  positions or more in the plane where the model's shape is not at a node of them all;
- by where else it shows: on the axial channels (the anchorage moving along the chord), in both planes at
  one frequency (a cable mode is in one plane), at a harmonic of a structural peak, or at a structural
  frequency the user gives.

The model's shapes are the undamped ones of the plane (:func:`~stcs_ident.forward.shapes.mode_shapes`) at
the tension and bending stiffness the family fit found; a damper's complex shape differs from them by its
phase, which the signed operating shape drops.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.errors import ComputationError, InputError
from ..forward.shapes import mode_shapes

__all__ = ["harmonic_of", "mac", "model_shapes", "shape_is_meaningful"]

#: The model's shape at the sensors must carry at least this share of its largest value over the span
#: (rms over the sensors; 0.15: below it every sensor sits near a node and the MAC compares noise).
MIN_SHAPE_SHARE = 0.15
#: Sensor positions closer than this fraction of the span count as one (a MAC needs two distinct points).
DISTINCT_POSITIONS = 0.01


def mac(shape: np.ndarray, model: np.ndarray) -> float:
    """Modal assurance criterion of two real shapes at the same points (NaN if either is zero)."""
    a, b = np.asarray(shape, float), np.asarray(model, float)
    denominator = float(a @ a) * float(b @ b)
    return float((a @ b) ** 2 / denominator) if denominator > 0 else float("nan")


def model_shapes(cable, attachments, tension: float, modes, positions, *, plane: str, tension_model: str,
                 tension_ratio: float = 1.0, EI_ratio: float = 1.0) -> tuple[np.ndarray, np.ndarray] | None:
    """The model's shapes of ``modes`` (1-based) at ``positions``, (n_positions, n) and their largest |φ| over
    the span (n,); None where the model cannot give them (a configuration its shape solver refuses)."""
    modes = np.asarray(modes, int)
    if modes.size == 0:
        return np.zeros((len(positions), 0)), np.zeros(0)
    try:
        shapes = mode_shapes(replace(cable, EI=cable.EI * EI_ratio), attachments, tension * tension_ratio,
                             int(modes.max()), tension_model=tension_model, plane=plane)
        span = np.linspace(0.0, shapes.nodes[-1], 401)
        at = shapes(np.clip(positions, 0.0, shapes.nodes[-1]))[:, modes - 1]
        largest = np.abs(shapes(span)[:, modes - 1]).max(axis=0)
    except (ComputationError, InputError, ValueError, np.linalg.LinAlgError):
        return None
    return at, largest


def shape_is_meaningful(positions: np.ndarray, model: np.ndarray, largest: float, length: float) -> bool:
    """Whether a MAC against ``model`` (the model's shape at ``positions``) can tell shapes apart: two distinct
    positions or more, and the shape not near a node at all of them."""
    distinct = np.unique(np.round(np.asarray(positions, float) / (DISTINCT_POSITIONS * length)))
    if distinct.size < 2 or not largest > 0:
        return False
    return float(np.sqrt(np.mean(np.asarray(model) ** 2))) >= MIN_SHAPE_SHARE * largest


def harmonic_of(frequency: float, sigma: float, bases, max_harmonic: int) -> tuple[float, int] | None:
    """The first (base frequency, order) of ``bases`` (each (frequency, 1σ)) whose harmonic of order 1 …
    ``max_harmonic`` lies within 3σ of ``frequency`` (σ combined: the peak's and order × the base's)."""
    for base, base_sigma in bases:
        for order in range(1, max_harmonic + 1):
            if abs(frequency - order * base) <= 3.0 * np.hypot(sigma, order * base_sigma):
                return float(base), order
    return None
