"""A batch of cable configurations, ready for the dynamic stiffness solvers.

:func:`build_batch` broadcasts a nominal configuration and its overrides
(tension, EI, length, attachment positions, masses, springs, dashpots, end
stiffnesses as arrays) into one :class:`~.assembly.CableBatch` per topology;
:func:`mode_items` lists the (configuration, mode) items a solver refines.
The undamped solver (:mod:`.dsm`) and the complex-mode solver
(:mod:`.damped`) both start from here.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence

import numpy as np

from ..core.errors import ModelError
from ..core.model import Attachment, Cable
from ..core.settings import TENSION_MODELS
from .assembly import CableBatch, Topology

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
    gcos = cable.gravity * cable.chord_cosine  # 0 for a vertical cable: no sag, no kinks
    # No weight normal to the chord (a vertical cable, or no gravity): no sag, so no sag-extensibility
    # (λ² = 0); the additional tension is coupled to nothing and is left out, as without EA (the in-plane
    # family is then the out-of-plane one, exactly, bar the attachments' springs and dampers per plane).
    model = tension_model if cable.EA is not None and gcos != 0 else "none"
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
            weight=m * gcos, gcos=_filled(count, gcos),
            positions=part["positions"], masses=part["masses"], springs=part["stiffnesses"],
            end_a=part["end_a"], end_b=part["end_b"], dashpots=part["coefficients"],
        )
        groups.append((batch, np.arange(n) if sel is None else sel))
    return shape, groups


class NominalBatch:
    """A nominal configuration's invariants for :func:`build_batch`, computed once: what builds a batch of
    it at many parameter sets without re-deriving them (a fit evaluates one model thousands of times, a
    few sets a call; the generic path's checks and broadcasts cost more than the solve there).

    :meth:`build` gives the batch :func:`build_batch` gives for the same sets, array for array, in the
    common case: parameter sets along one axis, one topology, values every check accepts. Otherwise
    (mixed topologies, a value out of range) it returns None and the caller uses :func:`build_batch`,
    which says what is wrong.
    """

    def __init__(self, cable: Cable, attachments: Sequence[Attachment], tension_model: str = "uniform"):
        _check_tension_model(tension_model)
        atts = sorted(attachments, key=lambda a: a.position)
        self.n_attachments = na = len(atts)
        self._scalars = {
            "EI": cable.EI, "length": cable.length, "mass_per_length": cable.mass_per_length,
            "end_a": cable.boundary_a.rotational_stiffness, "end_b": cable.boundary_b.rotational_stiffness,
        }
        self._per_att = {
            "positions": np.array([a.position for a in atts], float).reshape(na),
            "masses": np.array([a.mass for a in atts], float).reshape(na),
            "stiffnesses": np.array([a.stiffness for a in atts], float).reshape(na),
            "coefficients": np.array([getattr(a, "coefficient", 0.0) for a in atts], float).reshape(na),
        }
        self._gcos = gcos = cable.gravity * cable.chord_cosine
        self._EA = cable.EA if cable.EA is not None else np.inf
        self._model = tension_model if cable.EA is not None and gcos != 0 else "none"
        ends = [np.asarray(self._scalars[k], float) for k in ("end_a", "end_b", "EI")]
        self._nominal_topology = _topology(na, bool(np.isinf(ends[0])) or bool(ends[2] == 0),
                                           bool(np.isinf(ends[1])) or bool(ends[2] == 0), bool(ends[2] == 0),
                                           self._model)
        try:  # the nominal values as build_batch checks them (a fault is then its to name)
            self._valid = bool(_validate_inputs({"tension": np.asarray(1.0),
                                                 **{k: np.asarray(v, float) for k, v in self._scalars.items()}},
                                                self._per_att))
        except ModelError:
            self._valid = False

    def build(self, tension: np.ndarray, overrides: dict) -> CableBatch | None:
        """The batch of the sets ``tension`` (n,) and ``overrides`` (arrays (n,), per attachment (n,
        n_attachments)), as :func:`build_batch` builds it, or None where that path is needed."""
        part = self.flatten(tension, overrides)
        return None if part is None else merged_batch([part])

    def flatten(self, tension: np.ndarray, overrides: dict) -> tuple | None:
        """The sets ``tension`` (n,) and ``overrides`` as the arrays of a batch, checked, attachments in
        ascending order: (key, topology, arrays), where parts of one key can be solved as one batch
        (:func:`merged_batch`); None where :func:`build_batch` is needed."""
        n = tension.shape[0]
        na = self.n_attachments
        if not self._valid or n == 0 or tension.ndim != 1:
            return None
        flat = {"tension": tension}
        for key, v in overrides.items():
            if key in self._per_att:
                if v.shape != (n, na):
                    return None
            elif key not in self._scalars or v.shape != (n,):
                return None
            flat[key] = v
        if not _at_least(tension, 0.0, True):
            return None
        for key in ("length", "mass_per_length"):
            if key in overrides and not _at_least(overrides[key], 0.0, True):
                return None
        for key in ("EI", "masses", "stiffnesses", "coefficients"):
            if key in overrides and not _at_least(overrides[key], 0.0, False):
                return None
        for key in ("end_a", "end_b"):
            if key in overrides and not overrides[key].min() >= 0:  # NaN fails
                return None
        for key, value in self._scalars.items():
            if key not in flat:
                flat[key] = _filled(n, value)
        for key, value in self._per_att.items():
            if key not in flat:
                out = np.empty((n, na))
                out[...] = value
                flat[key] = out
        if na and ("positions" in overrides or "length" in overrides):
            pos = flat["positions"]
            if not ((pos > 0).all() and (pos < flat["length"][:, None]).all()):
                return None
            if na > 1 and not (pos[:, 1:] - pos[:, :-1] > 0).all():
                if np.any(np.diff(np.sort(pos, axis=1), axis=1) <= 0):
                    return None
                order = np.argsort(pos, axis=1)
                for k in self._per_att:
                    flat[k] = np.take_along_axis(flat[k], order, axis=1)
        topology = self._nominal_topology
        if "EI" in overrides or "end_a" in overrides or "end_b" in overrides:
            string = flat["EI"] == 0
            flags = (np.isinf(flat["end_a"]), np.isinf(flat["end_b"]), string)
            if not all(f.all() or not f.any() for f in flags):
                return None  # several topologies
            ca, cb, st = (bool(f[0]) for f in flags)
            topology = _topology(na, ca or st, cb or st, st, self._model)
        return (topology, self._gcos, self._EA), topology, flat


def merged_batch(parts: Sequence[tuple]) -> CableBatch:
    """One batch of the parts :meth:`NominalBatch.flatten` gave with one key, their sets one after the other:
    each set's arrays, and so its frequencies, are those of its part's batch alone (the batch's arithmetic
    is set by set)."""
    (_, gcos, EA), topology, flat = parts[0]
    if len(parts) > 1:
        flat = {k: np.concatenate([part[2][k] for part in parts]) for k in flat}
    n = flat["tension"].shape[0]
    m = flat["mass_per_length"]
    return CableBatch(
        topology,
        length=flat["length"], mass_per_length=m, EI=flat["EI"], tension=flat["tension"],
        EA=_filled(n, EA), weight=m * gcos, gcos=_filled(n, gcos),
        positions=flat["positions"], masses=flat["masses"], springs=flat["stiffnesses"],
        end_a=flat["end_a"], end_b=flat["end_b"], dashpots=flat["coefficients"],
    )


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


def mode_items(start, stop, n_modes):
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
