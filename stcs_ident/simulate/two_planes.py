"""Records of channels in both planes and along the cable, on a bridge whose anchorages move.

The kernel behind :func:`~stcs_ident.simulate.simulate.simulate_record` when it is given ``directions`` or a
:class:`~stcs_ident.simulate.bridge.BridgeConditions` (otherwise the in-plane record is made as it always
was). Each plane is simulated by :func:`~stcs_ident.simulate.excitation.plane_signal` on its own model
(:func:`~stcs_ident.core.planes.plane_view`: out-of-plane without sag-extensibility, springs at
``stiffness_out``, dampers at sin² of their angle; the planes uncoupled):

- in-plane: the blows' in-plane components and the ambient pressure, from the record's stream, in the order
  of the in-plane records (so an in-plane channel is what it was without this module);
- out-of-plane, only when a channel reads it: the blows' out-of-plane components and an independent ambient
  pressure of rms ``out_of_plane_ratio`` × the in-plane one (same correlation length), from a stream of its
  own; under a tension drift, the same drift (its sensitivities those of the out-of-plane modes);
- the anchorages' motion (:mod:`~stcs_ident.simulate.anchorage`), from a third stream.

A transverse channel whose sensor's true axis is at β (its stated direction plus the misalignment) reads
cos β · in + sin β · out; an axial channel reads the chord line's axial acceleration (cos δ of it, and sin δ
of the in-plane motion, misaligned by δ). Sensor noise (``snr_db``) is relative to each transverse channel's
rms; an axial channel gets the mean noise level of the transverse channels (the same sensors), or its own
signal's if there are none.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable, has_dampers
from ..core.planes import check_direction
from ..core.record import Record
from .anchorage import anchorage_motion, axial_response, transverse_response
from .bridge import BridgeConditions
from .conditions import FieldConditions, RecordTruth
from .damped_modes import damped_modes
from .disturbances import apply_sensor_disturbances, field_rng
from .excitation import (
    NYQUIST_FRACTION,
    Ambient,
    Impulse,
    PlaneSignal,
    Progress,
    check_damped_inputs,
    modal_basis,
    modal_damping,
    plane_model,
    plane_signal,
)

__all__ = ["check_channel_directions", "planes_record"]

#: Jumps of the record's bit generator that give the out-of-plane loading and the anchorages their own
#: streams (the field disturbances' stream is one jump: :func:`~stcs_ident.simulate.disturbances.field_rng`).
OUT_OF_PLANE_STREAM = 2
ANCHORAGE_STREAM = 3


def check_channel_directions(directions, n_channels: int) -> tuple[str | float, ...] | None:
    """One direction per channel (``"in"``, ``"out"``, ``"axial"`` or degrees), or None."""
    if directions is None:
        return None
    if isinstance(directions, str | bytes) or not hasattr(directions, "__iter__"):
        raise ModelError(f"must be a sequence of directions, one per position, got {directions!r}",
                         field="directions")
    values = tuple(check_direction(d, f"directions[{i}]") for i, d in enumerate(directions))
    if len(values) != n_channels:
        raise ModelError(f"gives {len(values)} directions for {n_channels} positions", field="directions")
    return values


def planes_record(cable: Cable, attachments: Sequence[Attachment], tension: float, x: np.ndarray, fs: float,
                  n_samples: int, names: tuple[str, ...], directions: tuple | None, *, damping,
                  impulses: Sequence[Impulse], ambient: Ambient | None, snr_db: float | None, n_modes: int | None,
                  seed, field: FieldConditions | None, bridge: BridgeConditions | None,
                  progress: Progress | None = None) -> tuple[Record, RecordTruth]:
    """The record of ``simulate_record_with_truth`` with channel directions and/or bridge conditions (checked
    by it, on the true model)."""
    if bridge is None:
        bridge = BridgeConditions()
    elif not isinstance(bridge, BridgeConditions):
        raise ModelError(f"must be a BridgeConditions or None, got {type(bridge).__name__}", field="bridge")
    n_ch = len(x)
    stated = directions if directions is not None else ("in",) * n_ch
    delta_deg = bridge.misalignment_per_channel(n_ch)
    delta = np.radians(delta_deg)
    # each transverse channel's true axis as (cos, sin) from in-plane; exact at multiples of 90° (an "out"
    # channel reads nothing of the in-plane motion, not cos(π/2) = 6e-17 of it)
    axes = [None if d == "axial" else _cos_sin(_degrees(d) + float(dl)) for d, dl in zip(stated, delta_deg)]
    axial = [a is None for a in axes]
    reads_in = [a[0] != 0.0 if a is not None else dl != 0.0 for a, dl in zip(axes, delta)]
    reads_out = [a is not None and a[1] != 0.0 for a in axes]
    check_damped_inputs(attachments, n_modes, damping)

    rng = np.random.default_rng(seed)
    own_rng = field_rng(rng) if field is not None else None
    need_out = any(reads_out)
    out_field_rng = copy.deepcopy(own_rng) if need_out and own_rng is not None else None  # the same drift
    out_rng = np.random.Generator(rng.bit_generator.jumped(OUT_OF_PLANE_STREAM)) if need_out else None
    anchor_rng = np.random.Generator(rng.bit_generator.jumped(ANCHORAGE_STREAM)) if bridge.moves_anchorages \
        else None

    model_in = plane_model(cable, attachments, "in")
    sig_in = plane_signal(*model_in, tension, x, fs, n_samples, damping=damping,
                          impulses=_plane_impulses(impulses, "in"), ambient=ambient, n_modes=n_modes, rng=rng,
                          own_rng=own_rng, field=field, progress=progress)
    model_out = plane_model(cable, attachments, "out")
    sig_out = None
    if need_out:
        ambient_out = None
        if ambient is not None and bridge.out_of_plane_ratio > 0:
            ambient_out = Ambient(ambient.rms_pressure * bridge.out_of_plane_ratio, ambient.correlation_length)
        sig_out = plane_signal(*model_out, tension, x, fs, n_samples, damping=damping,
                               impulses=_plane_impulses(impulses, "out"), ambient=ambient_out, n_modes=n_modes,
                               rng=out_rng, own_rng=out_field_rng, field=field)
    else:  # no channel reads it: its modes only, for the truth
        sig_out = _modes_only(model_out, tension, fs, n_samples, damping, n_modes)

    clean = np.zeros((n_samples, n_ch))
    transverse_in = sig_in.clean
    transverse_out = sig_out.clean if need_out else None
    motion = None
    if bridge.moves_anchorages:
        motion = anchorage_motion(bridge, n_samples, fs, anchor_rng)
        transverse_in = transverse_in + _anchorage_answer(motion, "in", sig_in, model_in, x, fs, n_samples)
        if need_out:
            transverse_out = transverse_out + _anchorage_answer(motion, "out", sig_out, model_out, x, fs, n_samples)
    along = axial_response(motion, x, cable.length, n_samples) if motion is not None and any(axial) else None
    for c in range(n_ch):
        if axial[c]:
            clean[:, c] = 0.0 if along is None else math.cos(delta[c]) * along[:, c]
            if reads_in[c]:
                clean[:, c] += math.sin(delta[c]) * transverse_in[:, c]
            continue
        cos_a, sin_a = axes[c]
        clean[:, c] = cos_a * transverse_in[:, c] if reads_in[c] else 0.0
        if reads_out[c]:
            clean[:, c] += sin_a * transverse_out[:, c]
    signal = _noisy(clean, snr_db, rng, axial)
    if field is not None:
        signal = apply_sensor_disturbances(signal, clean, fs, field, own_rng)
    truth = replace(sig_in.truth, out=None if sig_out is None else sig_out.truth,
                    structural=bridge.anchorage_motion,
                    misalignment=None if bridge.misalignment is None else bridge.misalignment_per_channel(n_ch),
                    channel_directions=directions, crossings=None if motion is None else motion.crossings)
    return Record(signal, fs, names, x, channel_directions=directions), truth


def _degrees(direction) -> float:
    """A transverse direction in degrees from in-plane."""
    return {"in": 0.0, "out": 90.0}.get(direction, direction) if isinstance(direction, str) else float(direction)


def _cos_sin(degrees: float) -> tuple[float, float]:
    """(cos, sin) of an angle in degrees, exact at multiples of 90°."""
    quarter, rest = divmod(degrees, 90.0)
    if rest == 0.0:
        return ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(quarter) % 4]
    return math.cos(math.radians(degrees)), math.sin(math.radians(degrees))


def _plane_impulses(impulses: Sequence[Impulse], plane: str) -> list[Impulse]:
    """The blows as they act in ``plane`` (in-plane blows unchanged, so the in-plane record is as before)."""
    out = []
    for imp in impulses:
        if imp.direction == plane == "in":
            out.append(imp)
        else:
            out.append(Impulse(imp.time, imp.position, imp.component(plane), plane))
    return out


def _modes_only(model, tension: float, fs: float, n_samples: int, damping, n_modes) -> PlaneSignal:
    """The out-of-plane modes (for the truth) when no channel reads that plane."""
    cable, atts = model
    if has_dampers(atts):
        modes = damped_modes(cable, atts, tension, fs, n_modes, lambda n: modal_damping(damping, n),
                             NYQUIST_FRACTION)
        return PlaneSignal(None, RecordTruth(modes.frequencies, tension, fs, n_samples, damping=modes.damping),
                           complex_modes=modes)
    shapes = modal_basis(cable, atts, tension, fs, n_modes)
    zeta = modal_damping(damping, len(shapes.frequencies))
    return PlaneSignal(None, RecordTruth(np.asarray(shapes.frequencies, float), tension, fs, n_samples,
                                         damping=zeta), shapes, zeta)


def _anchorage_answer(motion, plane: str, sig: PlaneSignal, model, x, fs, n_samples) -> np.ndarray:
    cable, atts = model
    modes = sig.complex_modes if sig.complex_modes is not None else sig.shapes
    return transverse_response(motion, plane, modes, sig.damping, atts, cable.length, cable.mass_per_length,
                               x, fs, n_samples)


def _noisy(clean: np.ndarray, snr_db: float | None, rng: np.random.Generator, axial: list[bool]) -> np.ndarray:
    """``clean`` plus white noise drawn as the in-plane records draw it; axial channels at the transverse
    channels' mean noise level."""
    if snr_db is None:
        return clean
    noise_rms = np.sqrt(np.mean(clean**2, axis=0)) * 10 ** (-snr_db / 20)
    axial = np.asarray(axial, bool)
    if axial.any() and (~axial).any():
        noise_rms[axial] = np.mean(noise_rms[~axial])
    return clean + rng.standard_normal(clean.shape) * noise_rms
