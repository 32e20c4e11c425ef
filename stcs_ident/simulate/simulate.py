"""Acceleration records from the forward model, by modal superposition.

The modes are the exact dynamic-stiffness model's natural frequencies and
mass-normalised shapes (:func:`~stcs_ident.forward.shapes.mode_shapes`).
Each modal coordinate obeys q̈ + 2ζω q̇ + ω² q = φᵀF(t) and a sensor at x
reads Σ_k φ_k(x) q̈_k(t). Nothing is time-stepped approximately:

- an impulse J at x₀ and t₀ starts each mode with q̇_k = φ_k(x₀) J, and its
  damped-sinusoid response is evaluated in closed form at the samples;
- ambient pressure is held constant over each sampling interval
  (zero-order hold, white up to the Nyquist frequency), and each mode is
  advanced by its exact state-transition matrix. The record starts from a
  state drawn from the stationary distribution, so it has no start-up
  transient (the kernels are in :mod:`~stcs_ident.simulate.modal_response`).

All modes below 0.45 × the sampling rate are kept (or a given number), so
a record has the realistic content of a band-limited sensor. Hidden
effects (:class:`~stcs_ident.simulate.effects.Effects`) act on the true
model only. :func:`~stcs_ident.simulate.simulate_campaign.simulate_campaign`
writes a whole campaign directory from them, for tests and benchmarks.

A cable with a :class:`~stcs_ident.core.model.Damper` among its true attachments
has non-proportional damping and complex modes: its records are made by
complex modal superposition of a finite-element model that carries the
dashpots exactly (:mod:`~stcs_ident.simulate.damped_response`), with the
same excitations and disturbances; ``damping`` is then the cable's own
(intrinsic) part. Without a damper nothing of that runs.

Field-like disturbances (coloured loading, a drifting tension, pink noise,
mains hum, offsets, float32 samples) are off by default and given as one
:class:`~stcs_ident.simulate.disturbances.FieldConditions`; without them a
record is exactly what it was before they existed.

Both planes, and a cable on a bridge (off by default): ``directions`` gives
each channel's direction (in-plane, out-of-plane, axial or an angle; a
biaxial or triaxial sensor is two or three channels at one position), and
:class:`~stcs_ident.simulate.bridge.BridgeConditions` the out-of-plane
loading's level, misaligned sensors, deck and pylon modes moving an
anchorage (a given list of frequencies and amplitudes) and traffic bursts.
The out-of-plane motion is that of the cable without sag-extensibility
(:func:`~stcs_ident.core.planes.plane_view`), loaded by its own independent
ambient pressure, uncoupled from the in-plane motion; the anchorages' motion
enters through the exact modal answer to a support motion
(:mod:`~stcs_ident.simulate.anchorage`). The truth says, per record, the
in-plane and out-of-plane frequencies and damping, the structural
frequencies, the misalignments and the crossings. Without these options
the record is exactly what it was before them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable, real_number
from ..core.record import Record
from .bridge import BridgeConditions, StructuralMode, Traffic
from .conditions import FieldConditions, RecordTruth
from .disturbances import apply_sensor_disturbances, check_field, field_rng
from .effects import Effects, true_model
from .excitation import (
    MAX_IMPULSES,
    MAX_SAMPLES,
    NYQUIST_FRACTION,
    UNCORRELATED_LENGTH,
    Ambient,
    Impulse,
    Progress,
    check_damped_inputs,
    check_impulses,
    check_positions,
    check_timing,
    modal_basis,
    modal_damping,
    plane_model,
    plane_signal,
    with_noise,
)
from .excitation import channel_names as named_channels
from .two_planes import check_channel_directions, planes_record

__all__ = [
    "MAX_IMPULSES", "MAX_SAMPLES", "NYQUIST_FRACTION", "UNCORRELATED_LENGTH", "Ambient", "BridgeConditions",
    "Effects", "FieldConditions", "Impulse", "Progress", "RecordTruth", "StructuralMode", "Traffic",
    "check_impulses", "check_timing", "modal_basis", "modal_damping", "simulate_record",
    "simulate_record_with_truth", "true_model",
]


def simulate_record(cable: Cable, attachments: Sequence[Attachment], tension: float, positions: Sequence[float], *,
                    duration: float, sampling_rate: float, damping: float | Sequence[float] = 0.005,
                    impulses: Sequence[Impulse] = (), ambient: Ambient | None = None, snr_db: float | None = None,
                    effects: Effects | None = None, n_modes: int | None = None,
                    seed: int | np.random.SeedSequence | None = 0, channel_names: Sequence[str] | None = None,
                    field: FieldConditions | None = None, progress: Progress | None = None,
                    directions: Sequence[str | float] | None = None, bridge: BridgeConditions | None = None) -> Record:
    """Simulate a multi-channel acceleration record of one configuration.

    Parameters
    ----------
    cable, attachments, tension :
        The nominal configuration (tension in N); ``effects`` turn it into
        the true one that vibrates.
    positions : sequence of float
        Sensor positions, m from end A, strictly inside the true span.
    duration : float
        s; the record has ``round(duration * sampling_rate)`` samples.
    sampling_rate : float
        Hz.
    damping : float or sequence of float
        Modal damping ratio(s), 0 < ζ < 1: one for all modes, or one per
        mode from mode 1 (at least as many as modes simulated; extra
        entries are ignored). With dampers, the cable's own (intrinsic)
        damping of its undamped modes; the dashpots add theirs.
    impulses : sequence of Impulse
        Blows, evaluated exactly.
    ambient : Ambient or None
        Distributed random pressure. At least one excitation is needed;
        with both, the blows' decays ride on the continuing ambient
        response (they add: the model is linear).
    snr_db : float or None
        Sensor noise: white Gaussian, per channel with rms = the channel's
        signal rms × 10^(−snr_db/20). None: noise-free.
    effects : Effects or None
        Hidden differences of the true model from the nominal one.
    n_modes : int or None
        Number of modes; default all below 0.45 × sampling rate. Every
        mode must lie below the Nyquist frequency.
    seed : int, SeedSequence or None
        For ``np.random.default_rng``; the same seed gives the same record,
        and the same signal with or without noise (noise is drawn last).
    channel_names : sequence of str or None
        Default ``"A1"``, ``"A2"``, ...
    field : FieldConditions or None
        Field-like disturbances (:mod:`~stcs_ident.simulate.disturbances`):
        low-pass ambient loading, tension drift, pink noise, mains hum, DC
        offsets, float32 samples. None (or ``FieldConditions()``): none,
        and the record is bit for bit the one without this argument. Their
        random draws use a stream of their own: turning on pink noise, hum,
        offsets or float32 leaves the signal and the white noise as they
        were; a coloured loading or a drift makes another signal.
    progress : callable(done, total), optional
        Called after each block of samples.
    directions : sequence or None
        One per entry of ``positions``: ``"in"`` (in-plane transverse),
        ``"out"`` (out-of-plane transverse), ``"axial"`` (along the chord)
        or an angle in degrees from in-plane towards out-of-plane. A
        position may repeat: a biaxial sensor is two entries at one x
        (``"in"``, ``"out"``), a triaxial one three. The record carries
        them (``Record.channel_directions``). None: every channel
        in-plane, and the record states no directions (as before they
        existed). When a channel reads out-of-plane motion, the
        out-of-plane modes are simulated too (:mod:`.two_planes`). An
        axial channel reads only the anchorages' axial motion (the cable's
        transverse modes give no axial acceleration to first order); its
        ``snr_db`` noise is at the transverse channels' mean noise level.
    bridge : BridgeConditions or None
        A cable on a bridge (:mod:`~stcs_ident.simulate.bridge`): the
        out-of-plane loading's level, misaligned sensors, deck and pylon
        modes moving an anchorage, traffic. None: none of it. A moving
        anchorage is an excitation by itself (no blow or ambient needed).

    Returns
    -------
    Record
        Acceleration in m/s² at the sensors.

    Raises
    ------
    ModelError
        For an invalid option; the field names it.

    See Also
    --------
    simulate_record_with_truth : the same record and what it truly holds
        (the time-averaged frequencies under a drift).
    """
    return simulate_record_with_truth(cable, attachments, tension, positions, duration=duration,
                                      sampling_rate=sampling_rate, damping=damping, impulses=impulses,
                                      ambient=ambient, snr_db=snr_db, effects=effects, n_modes=n_modes, seed=seed,
                                      channel_names=channel_names, field=field, progress=progress,
                                      directions=directions, bridge=bridge)[0]


def simulate_record_with_truth(cable: Cable, attachments: Sequence[Attachment], tension: float,
                               positions: Sequence[float], *, duration: float, sampling_rate: float,
                               damping: float | Sequence[float] = 0.005, impulses: Sequence[Impulse] = (),
                               ambient: Ambient | None = None, snr_db: float | None = None,
                               effects: Effects | None = None, n_modes: int | None = None,
                               seed: int | np.random.SeedSequence | None = 0,
                               channel_names: Sequence[str] | None = None, field: FieldConditions | None = None,
                               progress: Progress | None = None, directions: Sequence[str | float] | None = None,
                               bridge: BridgeConditions | None = None) -> tuple[Record, RecordTruth]:
    """:func:`simulate_record`'s record and what it truly holds.

    The parameters are :func:`simulate_record`'s. The
    :class:`~stcs_ident.simulate.disturbances.RecordTruth` gives the true
    model's frequencies and damping ratios (with dampers, the complex
    modes' |s|/2π and −Re(s)/|s|) and, under a tension drift, the relative tension at
    every sample, each mode's sensitivity to it, the instantaneous and the
    time-averaged frequencies. With ``directions`` or ``bridge`` it also
    gives the out-of-plane modes' truth (``out``, ``frequencies_out``,
    ``damping_out``; ``frequencies`` are the in-plane ones), the structural
    modes, each channel's misalignment and the traffic's crossing times.
    """
    fs, n_samples = check_timing(duration, sampling_rate)
    impulses = check_impulses(impulses)
    if snr_db is not None:
        snr_db = real_number(snr_db, "snr_db")
    if bridge is not None and not isinstance(bridge, BridgeConditions):
        raise ModelError(f"must be a BridgeConditions or None, got {type(bridge).__name__}", field="bridge")
    if not impulses and ambient is None and not (bridge is not None and bridge.moves_anchorages):
        raise ModelError("no excitation: give impulses, ambient and/or a moving anchorage", field="excitation")
    if ambient is not None and not isinstance(ambient, Ambient):
        raise ModelError(f"must be an Ambient or None, got {type(ambient).__name__}", field="ambient")
    cable, atts, tension = true_model(cable, attachments, tension, effects)
    x = check_positions(positions, cable.length, "positions")
    for imp in impulses:
        check_positions([imp.position], cable.length, "impulse.position")
    names = named_channels(channel_names, len(x))
    directions = check_channel_directions(directions, len(x))
    if bridge is not None:
        bridge.misalignment_per_channel(len(x))  # its count before any work
    if field is not None:
        check_field(field, len(x), fs, ambient is not None)
    if directions is not None or bridge is not None or any(imp.direction != "in" for imp in impulses):
        return planes_record(cable, atts, tension, x, fs, n_samples, names, directions, damping=damping,
                             impulses=impulses, ambient=ambient, snr_db=snr_db, n_modes=n_modes, seed=seed,
                             field=field, bridge=bridge, progress=progress)
    # in-plane channels only: the record as it was before the planes
    check_damped_inputs(atts, n_modes, damping)
    rng = np.random.default_rng(seed)
    own_rng = field_rng(rng) if field is not None else None
    plane = plane_signal(*plane_model(cable, atts, "in"), tension, x, fs, n_samples, damping=damping,
                         impulses=impulses, ambient=ambient, n_modes=n_modes, rng=rng, own_rng=own_rng, field=field,
                         progress=progress)
    signal = with_noise(plane.clean, snr_db, rng)
    if field is not None:
        signal = apply_sensor_disturbances(signal, plane.clean, fs, field, own_rng)
    return Record(signal, fs, names, x), plane.truth
