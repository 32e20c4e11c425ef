"""The acceleration record: a frozen dataclass in SI units.

Acceleration in m/s² (records in g are converted when read), shape
(n_samples, n_channels), each channel along its direction (in-plane
transverse unless the record says otherwise); channel positions are
metres from end A along the chord.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import ModelError
from .planes import check_direction

STANDARD_GRAVITY = 9.80665  # m/s² per g

#: Sampling rates a record may have (Hz): from one sample in 1000 s to ten times the highest frequency a
#: campaign may state (1 MHz). Outside, a unit or typing mistake (a rate of 1e300 Hz made the analysis
#: band empty deep inside the spectra instead of being refused where it is read).
SAMPLING_RATE_BAND = (1e-3, 1e7)


def sampling_rate(value, name: str = "sampling_rate", file: str | None = None) -> float:
    """``value`` as a sampling rate in :data:`SAMPLING_RATE_BAND`, Hz; ModelError naming ``name`` (and ``file``)
    otherwise. The one check of a sampling rate, for records read, built or simulated."""
    try:
        rate = float(value)
    except (TypeError, ValueError, OverflowError):
        rate = np.nan
    if isinstance(value, bool) or not np.isfinite(rate) or rate <= 0:
        raise ModelError(f"must be a finite number > 0 Hz, got {value!r}", field=name, file=file)
    low, high = SAMPLING_RATE_BAND
    if not low <= rate <= high:
        raise ModelError(f"must lie between {low:g} and {high:g} Hz (a unit or typing mistake), got {value!r}",
                         field=name, file=file)
    return rate


#: Temperatures a record may state, °C: beyond any structure's service (a unit or typing mistake outside).
TEMPERATURE_BAND = (-100.0, 150.0)


def check_temperature(value: Any, file: str | None) -> float:
    """``value`` as a temperature in :data:`TEMPERATURE_BAND`, °C; ModelError naming the file otherwise."""
    try:
        t = float(value)
    except (TypeError, ValueError, OverflowError):
        t = np.nan
    low, high = TEMPERATURE_BAND
    if isinstance(value, bool) or not low <= t <= high:
        raise ModelError(f"must be a number between {low:g} and {high:g} °C, got {value!r}", field="temperature",
                         file=file)
    return t


def check_shape(acceleration: np.ndarray, file: str | None) -> np.ndarray:
    if acceleration.ndim != 2:
        raise ModelError(f"must have shape (n_samples, n_channels), got {acceleration.shape}",
                         field="acceleration", file=file)
    if acceleration.shape[0] == 0 or acceleration.shape[1] == 0:
        raise ModelError(f"has no samples or no channels: shape {acceleration.shape}", field="acceleration", file=file)
    return acceleration


def check_names(names: Any, n_channels: int, file: str | None) -> list[str]:
    names = np.asarray(names, dtype=object)
    if names.shape != (n_channels,):
        raise ModelError(f"must have shape ({n_channels},), one per channel, got {names.shape}",
                         field="channel_name", file=file)
    seen = set()
    for index, name in enumerate(names):
        if not isinstance(name, str) or not name.strip():
            raise ModelError(f"channel {index} needs a non-empty text name, got {name!r}", field="channel_name",
                             file=file)
        if name in seen:
            raise ModelError(f"duplicate channel name {name!r}", field="channel_name", file=file)
        seen.add(name)
    return [str(name) for name in names]


def check_position_values(positions: Any, names: list[str], file: str | None) -> np.ndarray:
    if np.iscomplexobj(positions):  # numpy would drop the imaginary part (a warning, not an error)
        raise ModelError(f"positions must be real numbers (m from end A), got {np.asarray(positions).dtype}",
                         field="channel_position", file=file)
    try:
        positions = np.asarray(positions, dtype=float)
    except (TypeError, ValueError):
        raise ModelError("positions must be numbers", field="channel_position", file=file) from None
    if positions.shape != (len(names),):
        raise ModelError(f"must have shape ({len(names)},), one per channel, got {positions.shape}",
                         field="channel_position", file=file)
    bad = np.flatnonzero(~np.isfinite(positions))
    if bad.size:
        index = int(bad[0])
        raise ModelError(f"channel {names[index]!r} has position {positions[index]}: not a finite number",
                         field="channel_position", file=file)
    return positions


def check_directions(directions: Any, names: list[str], file: str | None) -> tuple[str | float, ...]:
    """One direction per channel (:func:`~stcs_ident.core.planes.check_direction`), ModelError naming the file
    and ``channel_direction`` otherwise."""
    values = list(np.asarray(directions, dtype=object).reshape(-1)) if not isinstance(directions, str) else [directions]
    if len(values) != len(names):
        raise ModelError(f"must have {len(names)} entries, one per channel, got {len(values)}",
                         field="channel_direction", file=file)
    out = []
    for name, value in zip(names, values):
        if isinstance(value, bytes):
            value = value.decode("utf-8", "replace")
        if isinstance(value, np.generic):
            value = value.item()
        try:
            out.append(check_direction(value, "channel_direction"))
        except ModelError as err:
            raise ModelError(f"channel {name!r}: {err.message}", field="channel_direction", file=file) from None
    return tuple(out)


#: Rows checked at a time by the scans of a whole record (bounded temporaries on a record of gigabytes).
BLOCK_ROWS = 65536


def check_finite(acceleration: np.ndarray, names: list[str], file: str | None) -> None:
    """Refuse NaN or inf samples, naming the first bad channel and sample (scanned in blocks of rows)."""
    bad_channels = np.zeros(acceleration.shape[1], dtype=bool)
    first = np.full(acceleration.shape[1], -1)
    for start in range(0, acceleration.shape[0], BLOCK_ROWS):
        bad = ~np.isfinite(acceleration[start:start + BLOCK_ROWS])
        new = bad.any(axis=0) & ~bad_channels
        first[new] = start + np.argmax(bad[:, new], axis=0)
        bad_channels |= new
    if not bad_channels.any():
        return
    bad_list = np.flatnonzero(bad_channels)
    channel = int(bad_list[0])
    sample = int(first[channel])
    value = acceleration[sample, channel]
    what = "NaN" if np.isnan(value) else f"{value:g}"
    others = f" ({bad_list.size - 1} other channel(s) too)" if bad_list.size > 1 else ""
    raise ModelError(f"channel {names[channel]!r} has {what} at sample {sample} (0-based), "
                     f"its first non-finite sample{others}", field="acceleration", file=file)


@dataclass(frozen=True, eq=False)
class Record:
    """A multi-channel acceleration record.

    Parameters
    ----------
    acceleration : ndarray (n_samples, n_channels), m/s²
    sampling_rate : float, Hz
    channel_names : tuple of str
    channel_positions : ndarray (n_channels,), m from end A
    start_time : str or None, ISO 8601
    source : str or None
        The file it was read from (for messages).
    dropped : tuple of (channel name, reason)
        Channels removed when the record was read (dead or clipped).
    temperature : float or None
        °C during the record (of the cable or the air, as the monitoring
        system gives it), for the temperature normalisation of ``track``.
    replaced : tuple of (option, given, file's value)
        The file's values that the campaign's ``record_format`` replaced
        (``("sampling_rate", 256.0, 255.9)``), for the report to say.
    channel_directions : tuple or None
        Per channel, ``"in"``, ``"out"``, ``"axial"`` or an angle in degrees
        (:mod:`stcs_ident.core.planes`); None when neither the file nor the
        campaign gives them: every channel is then read as in-plane
        (:attr:`directions`), and results say so.
    notes : tuple of str
        What the reader did that a user should know, one plain sentence each, without the file's name
        (``"header line found at line 7 (0-based) after a preamble: give header_row = 7 to fix it"``,
        ``"columns left out (not an acceleration unit): RECORD (RN), BattV (Volts)"``), for results to print.
    """

    acceleration: np.ndarray
    sampling_rate: float
    channel_names: tuple[str, ...]
    channel_positions: np.ndarray
    start_time: str | None = None
    source: str | None = None
    dropped: tuple[tuple[str, str], ...] = field(default_factory=tuple)
    temperature: float | None = None
    replaced: tuple[tuple[str, Any, Any], ...] = ()
    channel_directions: tuple[str | float, ...] | None = None
    notes: tuple[str, ...] = ()

    def __post_init__(self):
        file = self.source
        object.__setattr__(self, "replaced", tuple(tuple(item) for item in self.replaced))
        object.__setattr__(self, "notes", (self.notes,) if isinstance(self.notes, str) else
                           tuple(str(note) for note in self.notes))
        acc = np.asarray(self.acceleration, dtype=float)
        object.__setattr__(self, "acceleration", check_shape(acc[:, None] if acc.ndim == 1 else acc, file))
        object.__setattr__(self, "sampling_rate", sampling_rate(self.sampling_rate, file=file))
        names = check_names(self.channel_names, self.acceleration.shape[1], file)
        object.__setattr__(self, "channel_names", tuple(names))
        positions = np.asarray(self.channel_positions)
        object.__setattr__(self, "channel_positions", check_position_values(
            positions.reshape(-1) if np.iscomplexobj(positions) else np.asarray(positions, dtype=float).reshape(-1),
            names, file))
        if self.temperature is not None:
            object.__setattr__(self, "temperature", check_temperature(self.temperature, file))
        if self.channel_directions is not None:
            object.__setattr__(self, "channel_directions", check_directions(self.channel_directions, names, file))

    @property
    def directions(self) -> tuple[str | float, ...]:
        """Each channel's direction; ``"in"`` for all when the record has none (:attr:`channel_directions`)."""
        if self.channel_directions is None:
            return ("in",) * self.n_channels
        return self.channel_directions

    @property
    def n_samples(self) -> int:
        return self.acceleration.shape[0]

    @property
    def n_channels(self) -> int:
        return self.acceleration.shape[1]

    @property
    def duration(self) -> float:
        """Record length, s."""
        return self.n_samples / self.sampling_rate

    @property
    def time(self) -> np.ndarray:
        return np.arange(self.n_samples) / self.sampling_rate
