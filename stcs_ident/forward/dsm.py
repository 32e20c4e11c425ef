"""Natural frequencies of a cable by the exact dynamic stiffness method.

Public entry points:

- :func:`natural_frequencies`: the first N frequencies of one configuration;
- :func:`batch_frequencies`: the first N frequencies of many parameter sets
  at once (tension, EI, length, attachment positions, masses and springs,
  end stiffnesses as arrays), vectorised: the engine of identification;
- :func:`count_below`: the Wittrick–Williams count J(f).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..errors import ModelError
from ..model import Attachment, Cable
from .assembly import TENSION_MODELS, CableBatch, Topology
from .roots import solve_modes

#: Configurations solved together: bounds the memory of one evaluation
#: (items × dofs² doubles) while keeping numpy's per-call overhead small.
CHUNK = 8192

_OVERRIDES = ("tension", "EI", "length", "mass_per_length", "positions", "masses", "stiffnesses", "end_a", "end_b")


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
    }
    arrays = {k: np.asarray(v, float) for k, v in scalars.items()}
    att_arrays = {}
    for k, v in per_att.items():
        v = np.asarray(v, float)
        if v.ndim == 0 or v.shape[-1] != na:
            raise ModelError(f"last axis must have one value per attachment ({na})", field=k)
        att_arrays[k] = v
    shape = np.broadcast_shapes(*(a.shape for a in arrays.values()), *(a.shape[:-1] for a in att_arrays.values()))
    n = int(np.prod(shape, dtype=np.int64))
    flat = {k: np.broadcast_to(v, shape).reshape(n) for k, v in arrays.items()}
    flat.update({k: np.broadcast_to(v, shape + (na,)).reshape(n, na) for k, v in att_arrays.items()})
    _validate_arrays(flat)
    order = np.argsort(flat["positions"], axis=1)
    for k in per_att:
        flat[k] = np.take_along_axis(flat[k], order, axis=1)
    theta, g = cable.inclination, cable.gravity
    model = tension_model if cable.EA is not None else "none"
    groups = []
    clamped_a, clamped_b = np.isinf(flat["end_a"]), np.isinf(flat["end_b"])
    string = flat["EI"] == 0
    for ca, cb, st in {(bool(x), bool(y), bool(z)) for x, y, z in zip(clamped_a, clamped_b, string)}:
        sel = np.flatnonzero((clamped_a == ca) & (clamped_b == cb) & (string == st))
        topo = Topology(na, ca or st, cb or st, st, model)
        m = flat["mass_per_length"][sel]
        batch = CableBatch(
            topo,
            length=flat["length"][sel], mass_per_length=m, EI=flat["EI"][sel],
            tension=flat["tension"][sel],
            EA=np.full(len(sel), cable.EA if cable.EA is not None else np.inf),
            weight=m * g * math.cos(theta), gcos=np.full(len(sel), g * math.cos(theta)),
            positions=flat["positions"][sel], masses=flat["masses"][sel], springs=flat["stiffnesses"][sel],
            end_a=flat["end_a"][sel], end_b=flat["end_b"][sel],
        )
        groups.append((batch, sel))
    return shape, groups


def _validate_arrays(flat):
    for name in ("tension", "length", "mass_per_length"):
        v = flat[name]
        if not np.all(np.isfinite(v) & (v > 0)):
            raise ModelError("must be finite and > 0", field=name)
    for name in ("EI", "masses", "stiffnesses"):
        v = flat[name]
        if not np.all(np.isfinite(v) & (v >= 0)):
            raise ModelError("must be finite and >= 0", field=name)
    for name in ("end_a", "end_b"):
        v = flat[name]
        if np.any(np.isnan(v) | (v < 0)):
            raise ModelError("must be >= 0 (inf for clamped)", field=name)
    pos = flat["positions"]
    if pos.size:
        inside = (pos > 0) & (pos < flat["length"][:, None])
        if not np.all(inside):
            raise ModelError("attachments must lie strictly inside the span", field="positions")
        s = np.sort(pos, axis=1)
        if np.any(np.diff(s, axis=1) <= 0):
            raise ModelError("two attachments at one position", field="positions")


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
        ``masses``, ``stiffnesses``.

    Returns
    -------
    ndarray of shape ``broadcast_shape + (n_modes,)``
    """
    if int(n_modes) < 1:
        raise ModelError(f"must be >= 1, got {n_modes}", field="n_modes")
    n_modes = int(n_modes)
    shape, groups = build_batch(cable, attachments, tension, tension_model=tension_model, **overrides)
    total = int(np.prod(shape, dtype=np.int64))
    out = np.empty((total, n_modes))
    modes = np.arange(1, n_modes + 1)
    done = 0
    for batch, sel in groups:
        for start in range(0, len(sel), CHUNK):
            cfg = np.arange(start, min(start + CHUNK, len(sel)))
            config = np.repeat(cfg, n_modes)
            mode = np.tile(modes, len(cfg))
            omega = solve_modes(batch, config, mode)
            out[sel[cfg]] = omega.reshape(len(cfg), n_modes) / (2 * math.pi)
            done += len(cfg)
            if progress is not None:
                progress(done, total)
    return out.reshape(shape + (n_modes,))


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
