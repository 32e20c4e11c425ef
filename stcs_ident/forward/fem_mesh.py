"""Mesh and degree-of-freedom numbering of the finite-element cable model.

The input checks of :func:`~stcs_ident.forward.fem_assembly.fe_matrices`;
attachments merged by position; nodes at the ends and at the attachments,
with the elements shared between the segments in proportion to their
length (graded towards restrained ends on request); and the free-dof
numbering, node by node so the matrices stay banded, with a second
rotation at a string's attachments, where its slope may jump.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core.errors import ModelError
from ..core.model import (
    Attachment,
    Cable,
    finite_number,  # the model's check of a finite number, naming the field
)

__all__ = ["TENSION_MODELS", "Dofs", "check_inputs", "element_density", "merge_attachments", "mesh_nodes",
           "number_dofs"]

TENSION_MODELS = ("uniform", "none")


# ------------------------------------------------------------------ checks


def check_inputs(cable: Cable, tension: float, n_elements: int, tension_model: str, grading: float) -> float:
    """Check the arguments of ``fe_matrices``; the tension as a float. A bad one raises ModelError naming it."""
    if not isinstance(cable, Cable):
        raise ModelError("must be a Cable", field="cable")
    tension = finite_number(tension, "tension")
    if tension < 0:
        raise ModelError(f"must be >= 0, got {tension!r}", field="tension")
    if tension == 0 and cable.EI == 0:
        raise ModelError("must be > 0 for a string (EI = 0)", field="tension")
    if tension_model not in TENSION_MODELS:
        raise ModelError(f"must be one of {TENSION_MODELS}, got {tension_model!r}", field="tension_model")
    if tension == 0 and tension_model == "uniform" and cable.EA is not None:
        raise ModelError("must be > 0 for the sag term (or use tension_model='none')", field="tension")
    if isinstance(n_elements, bool) or not isinstance(n_elements, (int, np.integer)) or n_elements < 2:
        raise ModelError(f"must be an integer >= 2, got {n_elements!r}", field="n_elements")
    if finite_number(grading, "grading") < 0:
        raise ModelError(f"must be >= 0, got {grading!r}", field="grading")
    return tension


def merge_attachments(cable: Cable, attachments: Sequence[Attachment]) -> np.ndarray:
    """Rows (position, mass, stiffness) in position order, equal positions summed."""
    merged: dict[float, list[float]] = {}
    for a in attachments:
        if not isinstance(a, Attachment):
            raise ModelError(f"must hold Attachment objects, got {a!r}", field="attachments")
        if not 0 < a.position < cable.length:
            raise ModelError(
                f"position {a.position} m is outside the span (0, {cable.length}) m",
                field=f"attachment[{a.name}].position",
            )
        entry = merged.setdefault(a.position, [0.0, 0.0])
        entry[0] += a.mass
        entry[1] += a.stiffness
    rows = [(x, mass, spring) for x, (mass, spring) in sorted(merged.items())]
    return np.array(rows, dtype=float).reshape(-1, 3)


# -------------------------------------------------------------------- mesh


def element_density(cable: Cable, tension: float, grading: float):
    """Cumulative element density D(x) = ∫₀ˣ ρ, ρ = 1 + grading·e^{-d/δ}; None if uniform."""
    restrained_a = cable.boundary_a.rotational_stiffness > 0
    restrained_b = cable.boundary_b.rotational_stiffness > 0
    if grading == 0 or cable.EI == 0 or tension == 0 or not (restrained_a or restrained_b):
        return None
    layer = math.sqrt(cable.EI / tension)
    length = cable.length

    def cumulative(x: np.ndarray) -> np.ndarray:
        out = np.array(x, dtype=float)
        if restrained_a:
            out += grading * layer * -np.expm1(-x / layer)
        if restrained_b:
            out += grading * layer * (np.exp(-(length - x) / layer) - math.exp(-length / layer))
        return out

    return cumulative


def mesh_nodes(breaks: np.ndarray, n_elements: int, density) -> tuple[np.ndarray, np.ndarray]:
    """Node positions, and the node index of each attachment (interior break)."""
    weights = np.diff(breaks if density is None else density(breaks))
    counts = _allocate(weights, n_elements)
    pieces = [breaks[:1]]
    for j, n in enumerate(counts):
        lo, hi = breaks[j], breaks[j + 1]
        if density is None:
            xs = np.linspace(lo, hi, n + 1)
        else:
            xs = _invert_increasing(density, np.linspace(density(lo), density(hi), n + 1), lo, hi)
            xs[0], xs[-1] = lo, hi
        pieces.append(xs[1:])
    return np.concatenate(pieces), np.cumsum(counts)[:-1]


def _allocate(weights: np.ndarray, total: int) -> np.ndarray:
    """Split ``total`` elements over segments in proportion to ``weights``, at least 2 each.

    Largest-remainder rounding of the proportional share.
    """
    total = max(total, 2 * len(weights))
    share = weights / weights.sum() * total
    counts = np.maximum(np.floor(share).astype(int), 2)
    while counts.sum() < total:
        counts[np.argmax(share - counts)] += 1
    while counts.sum() > total:
        counts[np.argmax(np.where(counts > 2, counts - share, -np.inf))] -= 1
    return counts


def _invert_increasing(func, targets: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Solve func(x) = targets on [lo, hi] for an increasing func, by bisection.

    32 halvings place a node within 2^-32 of the segment: any mesh is
    valid, so only the grading, not the answer, depends on this precision.
    """
    a = np.full(targets.shape, lo)
    b = np.full(targets.shape, hi)
    for _ in range(32):
        mid = 0.5 * (a + b)
        below = func(mid) < targets
        a = np.where(below, mid, a)
        b = np.where(below, b, mid)
    return 0.5 * (a + b)


@dataclass(frozen=True)
class Dofs:
    """Free-dof numbering; -1 marks a fixed dof."""

    n: int
    disp: np.ndarray  # u at each node
    rot: np.ndarray  # (n_nodes, 2): θ seen from the left and from the right
    element: np.ndarray  # (n_elements, 4): u1, θ1, u2, θ2 of each element
    upper_bandwidth: int


def number_dofs(cable: Cable, n_nodes: int, att_nodes: np.ndarray) -> Dofs:
    """Number the dofs node by node (u, θ, [θ⁺]), which keeps the matrices banded.

    u is fixed at both ends; θ at a clamped end of a beam. For a string the
    slope may jump at an attachment, so that node gets a second rotation θ⁺
    for the element on its right.
    """
    beam = cable.EI > 0
    split = np.zeros(n_nodes, dtype=bool)
    if not beam:
        split[att_nodes] = True
    per_node = 2 + split
    first = np.concatenate(([0], np.cumsum(per_node)[:-1]))
    disp, rot_left = first, first + 1
    rot_right = rot_left + split
    fixed = [disp[0], disp[-1]]
    if beam and cable.boundary_a.is_clamped:
        fixed.append(rot_right[0])
    if beam and cable.boundary_b.is_clamped:
        fixed.append(rot_left[-1])
    keep = np.ones(per_node.sum(), dtype=bool)
    keep[fixed] = False
    renumber = np.where(keep, np.cumsum(keep) - 1, -1)
    element = renumber[np.column_stack((disp[:-1], rot_right[:-1], disp[1:], rot_left[1:]))]
    valid = np.where(element >= 0, element, np.iinfo(int).max)
    bandwidth = int(np.max(element.max(axis=1) - valid.min(axis=1)))
    return Dofs(
        n=int(keep.sum()),
        disp=renumber[disp],
        rot=renumber[np.column_stack((rot_left, rot_right))],
        element=element,
        upper_bandwidth=bandwidth,
    )
