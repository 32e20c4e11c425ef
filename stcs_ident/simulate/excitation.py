"""The pieces of a simulated record shared by its planes: excitations, modes, checks, one plane's signal.

:func:`plane_signal` is the noise-free response of one plane of transverse
motion to the blows and the ambient pressure, by the kernels of
:mod:`~stcs_ident.simulate.modal_response` (undamped modes),
:mod:`~stcs_ident.simulate.field_response` (coloured loading, drift) and
:mod:`~stcs_ident.simulate.damped_response` (a cable with dampers); the
model it is given is already that of the plane (:func:`plane_model`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable, Damper, has_dampers, real_number
from ..core.planes import check_direction, direction_angle, plane_view
from ..core.record import sampling_rate as record_sampling_rate
from ..forward.dsm import count_below
from ..forward.shapes import ModeShapes, mode_shapes
from .conditions import FieldConditions, RecordTruth
from .damped_modes import DampedModes, damped_modes
from .damped_response import damped_record
from .disturbances import lowpass_force_filter, relative_tension, tension_sensitivities
from .field_response import superpose_field
from .modal_response import matrix_sqrt, modal_force_covariance, superpose

__all__ = [
    "MAX_IMPULSES", "MAX_SAMPLES", "NYQUIST_FRACTION", "UNCORRELATED_LENGTH", "Ambient", "Impulse", "PlaneSignal",
    "Progress", "channel_names", "check_impulses", "check_positions", "check_timing", "modal_basis",
    "modal_damping", "plane_model", "plane_signal", "with_noise",
]

#: Modes are kept up to this fraction of the sampling rate (just below Nyquist).
NYQUIST_FRACTION = 0.45
#: Uncorrelated pressure: ``rms_pressure`` is the rms of its mean over this length (m).
UNCORRELATED_LENGTH = 1.0
#: Most samples of one simulated record (23 h at 200 Hz; 400 MB for 3 channels as float64, and several
#: times that while the modal responses are summed): a longer record is refused before anything is allocated.
MAX_SAMPLES = 2**24
#: Most hand blows in one record: each adds its free decay to every sample after it.
MAX_IMPULSES = 1000

Progress = Callable[[int, int], None]


@dataclass(frozen=True)
class Impulse:
    """A hand or hammer blow: an impulse at one point of the cable.

    Parameters
    ----------
    time : float
        s from the start of the record (may be negative: a blow before it).
    position : float
        m from end A.
    magnitude : float
        N s, positive in the direction of sag (in-plane) or of ``direction``.
    direction : "in", "out" or float
        Transverse direction of the blow: in-plane (the default), out-of-plane, or an angle in degrees from
        in-plane towards out-of-plane; the in-plane modes get cos β of it and the out-of-plane ones sin β.
    """

    time: float
    position: float
    magnitude: float
    direction: str | float = "in"

    def __post_init__(self):
        for name in ("time", "position", "magnitude"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"impulse.{name}"))
        direction = check_direction(self.direction, "impulse.direction")
        if direction == "axial":
            raise ModelError('must be transverse ("in", "out" or an angle in degrees): a blow along the cable '
                             "excites no transverse mode", field="impulse.direction")
        object.__setattr__(self, "direction", direction)

    def component(self, plane: str) -> float:
        """N s of the blow acting in ``plane`` ("in" or "out")."""
        if self.direction == "in":
            return self.magnitude if plane == "in" else 0.0
        if self.direction == "out":
            return self.magnitude if plane == "out" else 0.0
        angle = direction_angle(self.direction)
        if self.direction % 90.0 == 0.0:  # ±180°, -90°: exact, as "in" and "out" are
            c, s = round(math.cos(angle)), round(math.sin(angle))
        else:
            c, s = math.cos(angle), math.sin(angle)
        return self.magnitude * (c if plane == "in" else s)


@dataclass(frozen=True)
class Ambient:
    """Random pressure along the cable: Gaussian, white in time up to Nyquist.

    Parameters
    ----------
    rms_pressure : float
        N/m. With a correlation length, the pointwise rms; without one, the
        rms of the pressure averaged over each metre of cable
        (:data:`UNCORRELATED_LENGTH`), since a spatially white pressure has
        no pointwise value.
    correlation_length : float or None
        m; spatial correlation exp(−|x − x'| / L). None: uncorrelated along
        the cable, which loads every mode alike (∝ ∫φ_k²); a long L loads
        mainly the symmetric modes (∝ (∫φ_k)²).
    """

    rms_pressure: float
    correlation_length: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "rms_pressure", real_number(self.rms_pressure, "ambient.rms_pressure", positive=True))
        if self.correlation_length is not None:
            L = real_number(self.correlation_length, "ambient.correlation_length", positive=True)
            object.__setattr__(self, "correlation_length", L)




@dataclass(frozen=True, eq=False)
class PlaneSignal:
    """One plane's noise-free response and what it holds.

    ``shapes`` and ``damping`` are the undamped modes and their ratios (None for a cable with dampers, whose
    complex modes are ``complex_modes``, :mod:`~stcs_ident.simulate.damped_modes`'s).
    """

    clean: np.ndarray | None
    truth: RecordTruth
    shapes: ModeShapes | None = None
    damping: np.ndarray | None = None
    complex_modes: DampedModes | None = None


def plane_model(cable: Cable, attachments: Sequence[Attachment], plane: str) -> tuple[Cable, tuple]:
    """The model of ``plane``'s transverse motion (:func:`~stcs_ident.core.planes.plane_view`), its dampers'
    shares already taken (their ``angle`` set to 0), so the in-plane machinery simulates it as it is. For
    the in-plane motion of a model whose dampers all act in-plane (angle 0), the very same objects."""
    cable, atts = plane_view(cable, attachments, plane)
    atts = tuple(replace(a, angle=0.0) if isinstance(a, Damper) and a.angle != 0.0 else a for a in atts)
    return cable, atts


def plane_signal(cable: Cable, attachments: Sequence[Attachment], tension: float, x: np.ndarray, fs: float,
                 n_samples: int, *, damping, impulses: Sequence[Impulse], ambient: Ambient | None,
                 n_modes: int | None, rng: np.random.Generator, own_rng: np.random.Generator | None,
                 field: FieldConditions | None, progress: Progress | None = None) -> PlaneSignal:
    """The noise-free acceleration (n_samples, len(x)) of one plane's model and its truth.

    ``impulses`` act with their full ``magnitude`` (the caller gives each plane its component); ``rng`` makes
    the signal (start state, then the forces block by block), ``own_rng`` the drift's random walk (only
    ``field``'s loading and drift act here). The random draws are those of the records before the planes
    existed, so the in-plane signal is theirs bit for bit.
    """
    if has_dampers(attachments):
        load = None if ambient is None else (ambient.rms_pressure, ambient.correlation_length, UNCORRELATED_LENGTH)
        modes = damped_modes(cable, attachments, tension, fs, n_modes, lambda n: modal_damping(damping, n),
                             NYQUIST_FRACTION)
        clean, truth = damped_record(cable, attachments, tension, x, fs, n_samples,
                                     damping=lambda n: modal_damping(damping, n), n_modes=n_modes,
                                     band_fraction=NYQUIST_FRACTION, impulses=impulses, ambient_load=load,
                                     field=field, rng=rng, field_rng=own_rng, progress=progress, modes=modes)
        return PlaneSignal(clean, truth, complex_modes=modes)
    shapes = modal_basis(cable, attachments, tension, fs, n_modes)
    zeta = modal_damping(damping, len(shapes.frequencies))
    force_sqrt = None
    if ambient is not None:
        cov = modal_force_covariance(shapes, ambient.rms_pressure, ambient.correlation_length, length=cable.length,
                                     wave_speed=math.sqrt(tension / cable.mass_per_length),
                                     uncorrelated_length=UNCORRELATED_LENGTH)
        force_sqrt = matrix_sqrt(cov)
    kicks = [(imp.time, shapes([imp.position])[0] * imp.magnitude) for imp in impulses]
    truth = RecordTruth(np.asarray(shapes.frequencies, dtype=float), tension, fs, n_samples, damping=zeta)
    lowpass = field.ambient_lowpass if field is not None else None
    drift = field.drift if field is not None else None
    if lowpass is None and drift is None:
        clean = superpose(shapes, zeta, fs, n_samples, x, kicks, force_sqrt, rng, progress)
    else:
        if drift is not None:
            d = relative_tension(drift, n_samples, fs, own_rng)
            s = tension_sensitivities(cable, attachments, tension, len(shapes.frequencies))
            truth = RecordTruth(truth.frequencies, tension, fs, n_samples, d, s, damping=zeta)
        clean = superpose_field(shapes, zeta, fs, n_samples, x, kicks, force_sqrt, rng,
                                force_filter=None if lowpass is None else lowpass_force_filter(lowpass, fs),
                                relative_tension=truth.relative_tension, sensitivities=truth.sensitivities,
                                progress=progress)
    return PlaneSignal(clean, truth, shapes, zeta)


def check_damped_inputs(attachments: Sequence[Attachment], n_modes, damping) -> None:
    """With a damper among ``attachments``, the checks of ``n_modes`` and ``damping`` made before any work (the
    complex modes are solved first, and would take these values unchecked)."""
    if not has_dampers(attachments):
        return
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, int | np.integer)
                                or n_modes < 1):
        raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
    modal_damping(damping, 1)


def modal_basis(cable: Cable, attachments: Sequence[Attachment], tension: float, sampling_rate: float,
                n_modes: int | None = None) -> ModeShapes:
    """The modes a record at ``sampling_rate`` contains.

    Parameters
    ----------
    cable, attachments, tension :
        The configuration that vibrates (the true one).
    sampling_rate : float
        Hz.
    n_modes : int or None
        Default: all modes below ``NYQUIST_FRACTION × sampling_rate``.
        Given, every one of them must lie below the Nyquist frequency.

    Returns
    -------
    ModeShapes
        Frequencies (Hz) and mass-normalised shapes.

    Notes
    -----
    A massless, springless node is added at an irrational fraction of the
    span, away from the attachments: the shapes come from the nodal values
    of the dynamic stiffness, and without it a bare clamped cable has no
    nodal unknowns, and a mode with a node at every attachment has none
    that move. It changes no frequency or shape.
    """
    fs = float(sampling_rate)
    if n_modes is None:
        n = count_below(cable, attachments, tension, NYQUIST_FRACTION * fs)
        if n == 0:
            raise ModelError(f"no mode below {NYQUIST_FRACTION} x sampling rate ({fs:g} Hz): raise it",
                             field="sampling_rate")
    else:
        if isinstance(n_modes, bool) or not isinstance(n_modes, int | np.integer) or n_modes < 1:
            raise ModelError(f"must be an integer >= 1, got {n_modes!r}", field="n_modes")
        n = int(n_modes)
    shapes = mode_shapes(cable, attachments, tension, n)
    if shapes.frequencies[-1] >= fs / 2:
        raise ModelError(f"mode {n} at {shapes.frequencies[-1]:.4g} Hz is at or above the Nyquist frequency "
                         f"({fs / 2:g} Hz) and would alias", field="n_modes")
    return shapes


def modal_damping(damping: float | Sequence[float], n_modes: int) -> np.ndarray:
    """Damping ratios of the first ``n_modes`` modes, checked: 0 < ζ < 1."""
    try:
        values = np.atleast_1d(np.asarray(damping, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"must be a number or a sequence of numbers, got {damping!r}", field="damping") from None
    if values.ndim != 1:
        raise ModelError("must be a number or a sequence of numbers", field="damping")
    if values.size == 1 and np.ndim(damping) == 0:
        values = np.full(n_modes, values[0])
    if values.size < n_modes:
        raise ModelError(f"gives {values.size} ratios for {n_modes} modes", field="damping")
    values = values[:n_modes]
    if not np.all(np.isfinite(values) & (values > 0) & (values < 1)):
        raise ModelError("ratios must satisfy 0 < damping < 1", field="damping")
    return values


def with_noise(clean: np.ndarray, snr_db: float | None, rng: np.random.Generator) -> np.ndarray:
    if snr_db is None:
        return clean
    noise_rms = np.sqrt(np.mean(clean**2, axis=0)) * 10 ** (-snr_db / 20)
    return clean + rng.standard_normal(clean.shape) * noise_rms


def check_timing(duration, sampling_rate) -> tuple[float, int]:
    duration = real_number(duration, "duration", positive=True)
    fs = record_sampling_rate(sampling_rate)
    n = duration * fs
    if n > MAX_SAMPLES:
        raise ModelError(f"gives {n:.3g} samples at {fs:g} Hz; a simulated record has at most {MAX_SAMPLES} "
                         f"({MAX_SAMPLES / fs:.4g} s at this rate: memory grows with the samples)", field="duration")
    n = round(n)
    if n < 2:
        raise ModelError(f"gives {n} samples at {fs:g} Hz: at least 2 needed", field="duration")
    return fs, n


def check_impulses(impulses) -> tuple[Impulse, ...]:
    """The impulses (any iterable, read no further than one past the limit) as a checked tuple."""
    out = tuple(itertools.islice(impulses, MAX_IMPULSES + 1))
    if len(out) > MAX_IMPULSES:
        raise ModelError(f"more than {MAX_IMPULSES} hand blows; at most {MAX_IMPULSES} per record (each adds its "
                         "decay to every sample after it)", field="impulses")
    for imp in out:
        if not isinstance(imp, Impulse):
            raise ModelError(f"must hold Impulse objects, got {type(imp).__name__}", field="impulses")
    return out


def check_positions(positions, length: float, name: str) -> np.ndarray:
    try:
        x = np.atleast_1d(np.asarray(positions, dtype=float))
    except (TypeError, ValueError):
        raise ModelError(f"must be numbers (m), got {positions!r}", field=name) from None
    if x.ndim != 1 or x.size == 0:
        raise ModelError("must be a non-empty sequence of positions (m)", field=name)
    bad = ~(np.isfinite(x) & (x > 0) & (x < length))
    if bad.any():
        raise ModelError(f"{x[bad][0]!r} m is outside the (true) span (0, {length:g}) m", field=name)
    return x


def channel_names(names, n: int) -> tuple[str, ...]:
    if names is None:
        return tuple(f"A{i + 1}" for i in range(n))
    names = tuple(str(s) for s in names)
    if len(names) != n:
        raise ModelError(f"gives {len(names)} names for {n} positions", field="channel_names")
    return names
