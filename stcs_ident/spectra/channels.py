"""A record's channels by plane: the in-plane and out-of-plane transverse components, and the axial channels.

Each channel has a direction (:mod:`stcs_ident.core.planes`): ``"in"``, ``"out"``, ``"axial"`` or an angle θ
from the in-plane direction towards the out-of-plane one, so a transverse channel reads
a = cos θ · u + sin θ · v of the in-plane (u) and out-of-plane (v) accelerations at its position.

- Where one position has two or more transverse channels at directions at least ``MIN_SPREAD`` apart, u and v
  there are recovered by least squares (a sensor pair at 0° and 90° gives them as they are; a pair at 30° and
  120° is rotated): one channel per plane at that position.
- Any other transverse channel belongs to its nearer plane, divided by cos θ (in-plane) or sin θ
  (out-of-plane) so that it reads that plane's acceleration plus a leak of the other plane's
  (tan θ of it, none for a sensor aligned with its plane).
- Axial channels are not used for the cable's transverse families; they show the anchorage's motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.planes import PLANES, direction_angle, direction_plane
from ..core.record import Record

__all__ = ["PlaneChannels", "plane_channels", "plane_record"]

#: Two transverse channels at one position are rotated into in/out when their directions differ by at least
#: this (20°: the least-squares components' noise grows as 1/sin of the difference, 2.9 times at 20°).
MIN_SPREAD = math.radians(20.0)
#: Channels within this distance (m) are at one position.
SAME_POSITION = 1e-3


@dataclass(frozen=True)
class PlaneChannels:
    """The channels of one plane, each a linear combination of the record's channels.

    Attributes
    ----------
    plane : "in" or "out"
    names : tuple of str
        The record's channel name; ``a+b:in`` for a component rotated out of channels a and b.
    positions : ndarray (n,), m
    combinations : tuple of (indices, coefficients)
        Per channel of the plane, the record's columns and the weights that make it.
    """

    plane: str
    names: tuple[str, ...]
    positions: np.ndarray
    combinations: tuple[tuple[tuple[int, ...], tuple[float, ...]], ...]

    def __len__(self) -> int:
        return len(self.names)


def plane_channels(record: Record) -> tuple[dict[str, PlaneChannels], tuple[int, ...]]:
    """Per plane its channels (planes without any left out), and the indices of the axial channels."""
    directions = record.directions
    angles = [direction_angle(d) for d in directions]
    axial = tuple(k for k, a in enumerate(angles) if a is None)
    transverse = [k for k, a in enumerate(angles) if a is not None]
    parts: dict[str, list] = {p: [] for p in PLANES}
    done: set[int] = set()
    positions = record.channel_positions
    for k in transverse:
        if k in done:
            continue
        group = [j for j in transverse if j not in done and abs(positions[j] - positions[k]) <= SAME_POSITION]
        if _spread(angles[j] for j in group) >= MIN_SPREAD:
            done.update(group)
            A = np.array([[math.cos(angles[j]), math.sin(angles[j])] for j in group])
            inverse = np.linalg.pinv(A)  # (2, n): least-squares u and v
            aligned = sorted(directions[j] for j in group) == ["in", "out"]
            for row, plane in zip(inverse, PLANES):
                if aligned:
                    j = next(j for j in group if directions[j] == plane)
                    parts[plane].append((record.channel_names[j], positions[j], ((j,), (1.0,))))
                else:
                    name = "+".join(record.channel_names[j] for j in group) + f":{plane}"
                    parts[plane].append((name, positions[k], (tuple(group), tuple(float(c) for c in row))))
            continue
        done.add(k)
        plane = direction_plane(directions[k])
        gain = math.cos(angles[k]) if plane == "in" else math.sin(angles[k])
        gain = 1.0 if directions[k] in PLANES else gain  # exactly 1 for an aligned sensor
        parts[plane].append((record.channel_names[k], positions[k], ((k,), (1.0 / gain,))))
    out = {}
    for plane, items in parts.items():
        if items:
            out[plane] = PlaneChannels(plane, tuple(i[0] for i in items), np.array([i[1] for i in items], float),
                                       tuple(i[2] for i in items))
    return out, axial


def _spread(angles) -> float:
    """The largest angle between two of the transverse directions (as lines: 0 to 90°)."""
    values = list(angles)
    best = 0.0
    for i, a in enumerate(values):
        for b in values[i + 1:]:
            best = max(best, abs(math.asin(max(-1.0, min(1.0, math.sin(a - b))))))
    return best


def plane_record(record: Record, channels: PlaneChannels, extra: tuple[int, ...] = ()) -> Record:
    """The record of one plane's channels, then the record's channels ``extra`` as they are (no directions)."""
    x = record.acceleration
    columns = []
    for indices, coefficients in channels.combinations:
        if len(indices) == 1 and coefficients[0] == 1.0:
            columns.append(x[:, indices[0]])
        else:
            columns.append(x[:, list(indices)] @ np.asarray(coefficients))
    columns += [x[:, k] for k in extra]
    names = channels.names + tuple(record.channel_names[k] for k in extra)
    positions = np.concatenate([channels.positions, record.channel_positions[list(extra)]])
    return Record(acceleration=np.column_stack(columns), sampling_rate=record.sampling_rate,
                  channel_names=names, channel_positions=positions, start_time=record.start_time,
                  source=record.source, temperature=record.temperature)
