"""Natural frequencies of a cable by the exact dynamic stiffness method.

Public entry points:

- :func:`natural_frequencies`: the first N frequencies of one configuration;
- :func:`batch_frequencies`: the first N frequencies of many parameter sets
  at once (tension, EI, length, attachment positions, masses and springs,
  end stiffnesses as arrays), vectorised: the engine of identification;
- :class:`PreparedModel`: :func:`batch_frequencies` of one nominal configuration called many times
  (a fit's trial points), its invariants computed once;
- :func:`count_below`: the Wittrick–Williams count J(f).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable
from ..core.planes import plane_overrides, plane_view
from .batch import CHUNK, NominalBatch, build_batch, merged_batch, mode_items
from .damped import batch_complex_modes
from .roots import solve_modes


def batch_frequencies(cable: Cable, attachments: Sequence[Attachment], tension, n_modes: int = 6, *,
                      tension_model: str = "uniform", progress=None, plane: str | None = "in",
                      **overrides) -> np.ndarray:
    """First ``n_modes`` natural frequencies (Hz) of many parameter sets at once.

    Parameters
    ----------
    cable, attachments :
        The nominal configuration; any parameter not overridden is taken
        from here.
    tension : float or array
        H (N), broadcast against the overrides.
    n_modes : int
    tension_model : {"uniform", "per-segment", "none"}
    progress : callable(done, total), optional
        Called after each chunk of parameter sets.
    plane : {"in", "out"} or None
        The plane of the transverse motion (:func:`~stcs_ident.core.planes.plane_view`: out-of-plane, no
        sag-extensibility, springs at ``stiffness_out``, dampers at sin² of their angle); None takes the
        attachments' values as they are (already a plane's).
    **overrides :
        Arrays broadcast together with ``tension``: ``EI``, ``length``,
        ``mass_per_length``, ``end_a``, ``end_b`` (rotational stiffness,
        inf = clamped), and per attachment (last axis, one value per
        attachment in ascending nominal position) ``positions``,
        ``masses``, ``stiffnesses``, ``coefficients`` (a damper's dashpot,
        N s/m).

    With a dashpot (a :class:`~stcs_ident.core.model.Damper`) the modes are
    complex and the frequencies are |s|/2π (:mod:`.damped`).

    Returns
    -------
    ndarray of shape ``broadcast_shape + (n_modes,)``
    """
    if int(n_modes) < 1:
        raise ModelError(f"must be >= 1, got {n_modes}", field="n_modes")
    n_modes = int(n_modes)
    if plane is not None:
        overrides = plane_overrides(attachments, overrides, plane)
        cable, attachments = plane_view(cable, attachments, plane)
    if _damped(attachments, overrides):  # complex modes: the frequency is |s|/2π
        return np.abs(batch_complex_modes(cable, attachments, tension, n_modes, tension_model=tension_model,
                                          plane=None, **overrides)) / (2 * math.pi)
    shape, groups = build_batch(cable, attachments, tension, tension_model=tension_model, **overrides)
    total = math.prod(shape)
    if len(groups) == 1 and total <= CHUNK:  # the usual small batch: no scattering
        config, mode = mode_items(0, total, n_modes)
        out = solve_modes(groups[0][0], config, mode).reshape(total, n_modes) / (2 * math.pi)
        if progress is not None:
            progress(total, total)
        return out.reshape(shape + (n_modes,))
    out = np.empty((total, n_modes))
    done = 0
    for batch, sel in groups:
        for start in range(0, len(sel), CHUNK):
            stop = min(start + CHUNK, len(sel))
            config, mode = mode_items(start, stop, n_modes)
            omega = solve_modes(batch, config, mode)
            out[sel[start:stop]] = omega.reshape(stop - start, n_modes) / (2 * math.pi)
            done += stop - start
            if progress is not None:
                progress(done, total)
    return out.reshape(shape + (n_modes,))


class PreparedModel:
    """:func:`batch_frequencies` of one nominal configuration, for many calls with few parameter sets each.

    What does not change between calls (the plane's view of the attachments, their order, the nominal
    values and their checks, the topology) is worked out once; a call with the parameter sets along one
    axis then builds its batch directly (:class:`~.batch.NominalBatch`). The same batch, so the same
    frequencies bit for bit; any other call (a dashpot, mixed topologies, a value out of range, a batch
    beyond one chunk) goes through :func:`batch_frequencies` itself.
    """

    def __init__(self, cable: Cable, attachments: Sequence[Attachment], *, tension_model: str = "uniform",
                 plane: str | None = "in"):
        self.cable, self.attachments = cable, tuple(attachments)
        self.tension_model, self.plane = tension_model, plane
        viewed = (cable, self.attachments) if plane is None else plane_view(cable, self.attachments, plane)
        self._damped = _damped(viewed[1], {})
        self._nominal = None if self._damped else NominalBatch(*viewed, tension_model)
        # plane_overrides changes a per-attachment override only for a damper or an out-of-plane spring
        self._plane_keys = () if plane is None else (
            ("masses", "coefficients", "stiffnesses")
            if any(getattr(a, "angle", None) is not None for a in self.attachments) else
            ("stiffnesses",) if plane != "in" and any(getattr(a, "stiffness_out", None) is not None
                                                      for a in self.attachments) else ())

    def __call__(self, tension: np.ndarray, n_modes: int, overrides: dict) -> np.ndarray:
        """Frequencies (Hz), shape (n, n_modes), of the sets ``tension`` (n,) and ``overrides`` (as
        :func:`batch_frequencies` takes them)."""
        part = self.part(tension, overrides) if int(n_modes) >= 1 else None
        if part is None:
            return batch_frequencies(self.cable, self.attachments, tension, n_modes, tension_model=self.tension_model,
                                     plane=self.plane, **overrides)
        return solve_parts([part], [n_modes])[0]

    def part(self, tension: np.ndarray, overrides: dict) -> tuple | None:
        """The sets ``tension`` (n,) and ``overrides`` ready for :func:`solve_parts` (its first item the key of
        the parts that can be solved together), or None where only :meth:`__call__` can solve them."""
        if self._nominal is None or "coefficients" in overrides or tension.shape[0] > CHUNK:
            return None
        if self._plane_keys and any(k in overrides for k in self._plane_keys):
            overrides = plane_overrides(self.attachments, overrides, self.plane)
        return self._nominal.flatten(tension, overrides)


def solve_parts(parts: Sequence[tuple], n_modes: Sequence[int]) -> list[np.ndarray]:
    """The first ``n_modes[i]`` frequencies (Hz), (n_i, n_modes[i]), of each of ``parts`` (of one key, from
    :meth:`PreparedModel.part`; several models' parts, of one cable) in one solve: each set's frequencies are
    those it has solved alone, bit for bit."""
    batch = merged_batch(parts)
    sizes = [part[2]["tension"].shape[0] for part in parts]
    if len(parts) == 1:
        config, mode = mode_items(0, sizes[0], int(n_modes[0]))
    else:
        config, mode = _merged_items(tuple(sizes), tuple(int(q) for q in n_modes))
    omega = solve_modes(batch, config, mode) / (2 * math.pi)
    out, k = [], 0
    for n, q in zip(sizes, n_modes):
        out.append(omega[k:k + n * int(q)].reshape(n, int(q)))
        k += n * int(q)
    return out


@functools.lru_cache(maxsize=256)
def _merged_items(sizes: tuple[int, ...], n_modes: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The (configuration, mode) items of parts of ``sizes`` sets one after the other, each part's modes 1 to
    its ``n_modes`` (shared between calls, so read-only)."""
    starts = np.cumsum([0, *sizes])
    config = np.concatenate([np.repeat(np.arange(a, a + n, dtype=np.int64), q) for a, n, q in zip(starts, sizes, n_modes)])
    mode = np.concatenate([np.tile(np.arange(1, q + 1, dtype=np.int64), n) for n, q in zip(sizes, n_modes)])
    config.flags.writeable = mode.flags.writeable = False
    return config, mode


def _damped(attachments, overrides) -> bool:
    """Whether a dashpot is on: a damper among the attachments, or a non-zero ``coefficients`` override."""
    if "coefficients" in overrides:
        return bool(np.any(np.asarray(overrides["coefficients"], float) != 0))
    return any(getattr(a, "coefficient", 0.0) for a in attachments)


def natural_frequencies(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int = 6, *,
                        tension_model: str = "uniform", plane: str | None = "in") -> np.ndarray:
    """The first ``n_modes`` natural frequencies (Hz) of one configuration.

    Exact for the model of ``docs/model.md`` (segments between attachments solved
    in closed form); found by the Wittrick–Williams count, so none is missed,
    and refined to 1e-12 relative. ``plane``: ``"in"`` (in-plane) or ``"out"`` (out-of-plane,
    :func:`~stcs_ident.core.planes.plane_view`).
    """
    return batch_frequencies(cable, attachments, float(tension), n_modes, tension_model=tension_model, plane=plane)


def count_below(cable: Cable, attachments: Sequence[Attachment], tension: float, frequency: float, *,
                tension_model: str = "uniform", plane: str = "in") -> int:
    """Number of natural frequencies strictly below ``frequency`` (Hz) in ``plane``: J(ω)."""
    cable, attachments = plane_view(cable, attachments, plane)
    _, [(batch, _)] = build_batch(cable, attachments, float(tension), tension_model=tension_model)
    J, _, _ = batch.evaluate(np.array([0]), np.array([2 * math.pi * float(frequency)]))
    return int(J[0])
