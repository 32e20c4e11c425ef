"""Natural frequencies of a cable by the exact dynamic stiffness method.

Public entry points:

- :func:`natural_frequencies`: the first N frequencies of one configuration;
- :func:`batch_frequencies`: the first N frequencies of many parameter sets
  at once (tension, EI, length, attachment positions, masses and springs,
  end stiffnesses as arrays), vectorised: the engine of identification;
- :func:`count_below`: the Wittrick–Williams count J(f).
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable
from .assembly import TENSION_MODELS, CableBatch, Topology
from .roots import solve_modes

#: Configurations solved together: bounds the memory of one evaluation
#: (items × dofs² doubles) while keeping numpy's per-call overhead small.
CHUNK = 8192

_OVERRIDES = ("tension", "EI", "length", "mass_per_length", "positions", "masses", "stiffnesses", "end_a", "end_b",
              "coefficients")


def _check_tension_model(tension_model: str) -> None:
    if tension_model not in TENSION_MODELS:
        raise ModelError(f"must be one of {', '.join(TENSION_MODELS)}, got {tension_model!r}", field="tension_model")


def build_batch(cable: Cable, attachments: Sequence[Attachment], tension, *, tension_model="uniform", **overrides):
    """Broadcast parameters to one array shape and build the batches.

    Returns
    -------
    shape : tuple
        The broadcast shape of the parameter sets.
    groups : list of (CableBatch, indices)
        One batch per topology (clamped or not at each end, EI zero or not),
        with the flat indices of its parameter sets.
    """
    _check_tension_model(tension_model)
    unknown = set(overrides) - set(_OVERRIDES)
    if unknown:
        raise ModelError(f"unknown parameter(s) {sorted(unknown)}", field="overrides")
    atts = sorted(attachments, key=lambda a: a.position)
    na = len(atts)
    scalars = {
        "tension": tension,
        "EI": overrides.get("EI", cable.EI),
        "length": overrides.get("length", cable.length),
        "mass_per_length": overrides.get("mass_per_length", cable.mass_per_length),
        "end_a": overrides.get("end_a", cable.boundary_a.rotational_stiffness),
        "end_b": overrides.get("end_b", cable.boundary_b.rotational_stiffness),
    }
    per_att = {
        "positions": overrides.get("positions", [a.position for a in atts]),
        "masses": overrides.get("masses", [a.mass for a in atts]),
        "stiffnesses": overrides.get("stiffnesses", [a.stiffness for a in atts]),
        "coefficients": overrides.get("coefficients", [getattr(a, "coefficient", 0.0) for a in atts]),
    }
    arrays = {k: np.asarray(v, float) for k, v in scalars.items()}
    att_arrays = {}
    for k, v in per_att.items():
        v = np.asarray(v, float)
        if v.ndim == 0 or v.shape[-1] != na:
            raise ModelError(f"last axis must have one value per attachment ({na})", field=k)
        att_arrays[k] = v
    shapes = [a.shape for a in arrays.values()] + [a.shape[:-1] for a in att_arrays.values()]
    distinct = set(shapes) - {()}
    shape = np.broadcast_shapes(*shapes) if len(distinct) > 1 else (distinct.pop() if distinct else ())
    n = math.prod(shape)
    # Checked before broadcasting (every value reaches some parameter set when there is one), so
    # a value repeated over the batch is checked once; an empty batch has nothing to check.
    ascending = _validate_inputs(arrays, att_arrays) if n else True
    flat = {k: _flat(v, shape, n) for k, v in arrays.items()}
    flat.update({k: _flat(v, shape, n, na) for k, v in att_arrays.items()})
    if not ascending:
        order = np.argsort(flat["positions"], axis=1)
        for k in per_att:
            flat[k] = np.take_along_axis(flat[k], order, axis=1)
    theta, g = cable.inclination, cable.gravity
    model = tension_model if cable.EA is not None else "none"
    ends = (arrays["end_a"], arrays["end_b"], arrays["EI"])
    if not n:
        kinds = []
    elif all(a.ndim == 0 for a in ends):  # not overridden: one topology
        kinds = [(bool(np.isinf(ends[0])), bool(np.isinf(ends[1])), bool(ends[2] == 0), None)]
    else:
        clamped_a, clamped_b = np.isinf(flat["end_a"]), np.isinf(flat["end_b"])
        string = flat["EI"] == 0
        flags = (clamped_a, clamped_b, string)
        if all(f.all() or not f.any() for f in flags):
            kinds = [(bool(clamped_a[0]), bool(clamped_b[0]), bool(string[0]), None)]
        else:
            kinds = [(ca, cb, st, np.flatnonzero((clamped_a == ca) & (clamped_b == cb) & (string == st)))
                     for ca, cb, st in {(bool(x), bool(y), bool(z)) for x, y, z in zip(*flags)}]
    groups = []
    for ca, cb, st, sel in kinds:
        topo = _topology(na, ca or st, cb or st, st, model)
        part = flat if sel is None else {k: v[sel] for k, v in flat.items()}
        m = part["mass_per_length"]
        count = len(m)
        batch = CableBatch(
            topo,
            length=part["length"], mass_per_length=m, EI=part["EI"],
            tension=part["tension"],
            EA=_filled(count, cable.EA if cable.EA is not None else np.inf),
            weight=m * g * math.cos(theta), gcos=_filled(count, g * math.cos(theta)),
            positions=part["positions"], masses=part["masses"], springs=part["stiffnesses"],
            end_a=part["end_a"], end_b=part["end_b"], dashpots=part["coefficients"],
        )
        groups.append((batch, np.arange(n) if sel is None else sel))
    return shape, groups


@functools.lru_cache(maxsize=256)
def _topology(n_attachments, clamped_a, clamped_b, string, tension_model):
    return Topology(n_attachments, clamped_a, clamped_b, string, tension_model)


def _filled(n, value):
    out = np.empty(n)
    out.fill(value)
    return out


def _flat(v, shape, n, *tail):
    """``v`` broadcast to ``shape + tail`` as an (n, *tail) array (a view when it has that shape)."""
    full = shape + tail
    if v.shape == full:
        return v.reshape((n,) + tail)
    out = np.empty((n,) + tail)
    out.reshape(full)[...] = v
    return out


#: Up to this many values a check runs on a Python list (cheaper than numpy's reductions).
_FEW = 64


def _at_least(v, low, strict):
    """Whether every value of ``v`` is finite and > ``low`` (``strict``) or >= ``low``."""
    if v.size <= _FEW:  # NaN fails every comparison, inf the upper one
        values = v.ravel().tolist()
        if strict:
            return all(low < x < math.inf for x in values)
        return all(low <= x < math.inf for x in values)
    lo = v.min()
    return bool((lo > low if strict else lo >= low) and v.max() < math.inf)


def _validate_inputs(arrays, att_arrays):
    """Check the parameter values (before broadcasting); whether every row's positions ascend."""
    for name in ("tension", "length", "mass_per_length"):
        if not _at_least(arrays[name], 0.0, True):
            raise ModelError("must be finite and > 0", field=name)
    for name, v in (("EI", arrays["EI"]), ("masses", att_arrays["masses"]),
                    ("stiffnesses", att_arrays["stiffnesses"]), ("coefficients", att_arrays["coefficients"])):
        if not _at_least(v, 0.0, False):
            raise ModelError("must be finite and >= 0", field=name)
    for name in ("end_a", "end_b"):
        v = arrays[name]
        if not (all(x >= 0 for x in v.ravel().tolist()) if v.size <= _FEW else v.min() >= 0):  # NaN fails
            raise ModelError("must be >= 0 (inf for clamped)", field=name)
    pos = att_arrays["positions"]
    if not pos.size:
        return True
    length = arrays["length"]
    if length.ndim == 0 and pos.size <= _FEW:
        span = float(length)
        rows = pos.reshape(-1, pos.shape[-1]).tolist()
        if not all(0 < x < span for row in rows for x in row):
            raise ModelError("attachments must lie strictly inside the span", field="positions")
        if all(a < b for row in rows for a, b in itertools.pairwise(row)):
            return True
    else:
        if not ((pos > 0).all() and (pos < length[..., None]).all()):
            raise ModelError("attachments must lie strictly inside the span", field="positions")
        if pos.shape[-1] < 2 or (pos[..., 1:] - pos[..., :-1] > 0).all():
            return True
    s = np.sort(pos, axis=-1)
    if np.any(s[..., 1:] - s[..., :-1] <= 0):
        raise ModelError("two attachments at one position", field="positions")
    return False


def batch_frequencies(cable: Cable, attachments: Sequence[Attachment], tension, n_modes: int = 6, *,
                      tension_model: str = "uniform", progress=None, **overrides) -> np.ndarray:
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
    if _damped(attachments, overrides):  # complex modes: the frequency is |s|/2π
        from .damped import batch_complex_modes

        return np.abs(batch_complex_modes(cable, attachments, tension, n_modes, tension_model=tension_model,
                                          **overrides)) / (2 * math.pi)
    shape, groups = build_batch(cable, attachments, tension, tension_model=tension_model, **overrides)
    total = math.prod(shape)
    if len(groups) == 1 and total <= CHUNK:  # the usual small batch: no scattering
        config, mode = _items(0, total, n_modes)
        out = solve_modes(groups[0][0], config, mode).reshape(total, n_modes) / (2 * math.pi)
        if progress is not None:
            progress(total, total)
        return out.reshape(shape + (n_modes,))
    out = np.empty((total, n_modes))
    done = 0
    for batch, sel in groups:
        for start in range(0, len(sel), CHUNK):
            stop = min(start + CHUNK, len(sel))
            config, mode = _items(start, stop, n_modes)
            omega = solve_modes(batch, config, mode)
            out[sel[start:stop]] = omega.reshape(stop - start, n_modes) / (2 * math.pi)
            done += stop - start
            if progress is not None:
                progress(done, total)
    return out.reshape(shape + (n_modes,))


def _damped(attachments, overrides) -> bool:
    """Whether a dashpot is on: a damper among the attachments, or a non-zero ``coefficients`` override."""
    if "coefficients" in overrides:
        return bool(np.any(np.asarray(overrides["coefficients"], float) != 0))
    return any(getattr(a, "coefficient", 0.0) for a in attachments)


def _items(start, stop, n_modes):
    """(configuration, mode) of every item of configurations ``start:stop``, modes 1..n_modes."""
    if start == 0 and stop <= 256:
        return _small_items(stop, n_modes)
    config = np.repeat(np.arange(start, stop, dtype=np.int64), n_modes)
    mode = np.tile(np.arange(1, n_modes + 1, dtype=np.int64), stop - start)
    return config, mode


@functools.lru_cache(maxsize=256)
def _small_items(count, n_modes):
    """The items of a small batch, shared between calls (so read-only)."""
    config = np.repeat(np.arange(count, dtype=np.int64), n_modes)
    mode = np.tile(np.arange(1, n_modes + 1, dtype=np.int64), count)
    config.flags.writeable = mode.flags.writeable = False
    return config, mode


def natural_frequencies(cable: Cable, attachments: Sequence[Attachment], tension: float, n_modes: int = 6, *,
                        tension_model: str = "uniform") -> np.ndarray:
    """The first ``n_modes`` natural frequencies (Hz) of one configuration.

    Exact for the model of ``docs/model.md`` (segments between attachments solved
    in closed form); found by the Wittrick–Williams count, so none is missed,
    and refined to 1e-12 relative.
    """
    return batch_frequencies(cable, attachments, float(tension), n_modes, tension_model=tension_model)


def count_below(cable: Cable, attachments: Sequence[Attachment], tension: float, frequency: float, *,
                tension_model: str = "uniform") -> int:
    """Number of natural frequencies strictly below ``frequency`` (Hz): J(ω)."""
    _, [(batch, _)] = build_batch(cable, attachments, float(tension), tension_model=tension_model)
    J, _, _ = batch.evaluate(np.array([0]), np.array([2 * math.pi * float(frequency)]))
    return int(J[0])
