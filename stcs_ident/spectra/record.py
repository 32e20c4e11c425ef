"""The acceleration record: a frozen dataclass in SI units.

Acceleration is transverse and in-plane, m/s² (records in g are converted
when read), shape (n_samples, n_channels); channel positions are metres
from end A along the chord.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ModelError

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
    """

    acceleration: np.ndarray
    sampling_rate: float
    channel_names: tuple[str, ...]
    channel_positions: np.ndarray
    start_time: str | None = None
    source: str | None = None
    dropped: tuple[tuple[str, str], ...] = field(default_factory=tuple)

    def __post_init__(self):
        acc = np.asarray(self.acceleration, dtype=float)
        if acc.ndim == 1:
            acc = acc[:, None]
        if acc.ndim != 2:
            raise ModelError(f"must have shape (n_samples, n_channels), got {acc.shape}", field="acceleration")
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "sampling_rate", sampling_rate(self.sampling_rate, file=self.source))
        names = tuple(str(n) for n in self.channel_names)
        if len(names) != acc.shape[1]:
            raise ModelError(f"has {len(names)} names for {acc.shape[1]} channels", field="channel_name")
        if len(set(names)) != len(names):
            raise ModelError("channel names must be unique", field="channel_name")
        object.__setattr__(self, "channel_names", names)
        pos = np.asarray(self.channel_positions, dtype=float).reshape(-1)
        if pos.shape != (acc.shape[1],):
            raise ModelError(f"has {pos.size} positions for {acc.shape[1]} channels", field="channel_position")
        object.__setattr__(self, "channel_positions", pos)

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
