"""A whole simulated campaign directory, for tests and benchmarks.

:func:`simulate_campaign` turns a nominal campaign into a campaign
directory whose records come from a true model that may differ from it
(:class:`~stcs_ident.simulate.effects.Effects`), and writes the truth
beside it in ``truth.json`` for scoring identification and diagnosis.
Field-like disturbances (:class:`~stcs_ident.simulate.disturbances.FieldConditions`)
may be given for all tests or per test; a test with a tension drift gets
its time-averaged frequencies in ``truth.json``. Channel directions (biaxial, triaxial sensors) and bridge
conditions (:class:`~stcs_ident.simulate.bridge.BridgeConditions`) may be given too; ``truth.json`` then holds
per test the in-plane and out-of-plane frequencies, the structural ones, the misalignments and the crossings.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..core.errors import ModelError
from ..core.files import whole_directory
from ..core.model import Attachment, Cable, Campaign, Damper, Test, has_dampers
from ..core.planes import direction_text
from ..forward.dsm import natural_frequencies
from ..io.campaign import CAMPAIGN_FILE, campaign_to_toml
from .bridge import BridgeConditions
from .conditions import FieldConditions
from .disturbances import write_record_as
from .effects import Effects, true_model
from .simulate import (
    Ambient,
    Impulse,
    Progress,
    check_impulses,
    check_timing,
    modal_basis,
    modal_damping,
    simulate_record_with_truth,
)
from .two_planes import check_channel_directions

__all__ = ["TRUTH_FILE", "simulate_campaign"]

#: The file, beside ``campaign.toml``, that holds the true model.
TRUTH_FILE = "truth.json"

def simulate_campaign(campaign: Campaign, out_dir: str | os.PathLike, *, positions: Sequence[float],
                      duration: float, sampling_rate: float, tests: Sequence[str] | None = None,
                      damping: float | Sequence[float] = 0.005, impulses: Sequence[Impulse] = (),
                      ambient: Ambient | None = None, snr_db: float | None = None,
                      effects: Effects | Mapping[str, Effects] | None = None, n_modes: int | None = None,
                      seed: int = 0, channel_names: Sequence[str] | None = None, overwrite: bool = False,
                      field: FieldConditions | Mapping[str, FieldConditions] | None = None,
                      progress: Progress | None = None, directions: Sequence[str | float] | None = None,
                      bridge: BridgeConditions | Mapping[str, BridgeConditions] | None = None) -> Path:
    """Write a campaign directory whose records come from a (hidden) true model.

    ``out_dir`` gets ``records/<test>.h5`` for each selected test,
    ``campaign.toml`` describing the **nominal** campaign only (its cable,
    setups and the selected tests, each with ``record`` and without
    ``frequencies``), and ``truth.json`` with the true parameters and
    natural frequencies per test (not referenced by the campaign; for a
    setup with dampers, the complex modes' frequencies |s|/2π, their damping
    ratios under ``"mode_damping"`` and each damper's ``"coefficient"``). The
    directory appears whole or not at all: it is built beside ``out_dir``
    under a temporary name, then renamed.

    Parameters
    ----------
    campaign : Campaign
        The nominal campaign.
    out_dir : path-like
        Must not exist, or be empty, unless ``overwrite``.
    positions, duration, sampling_rate, damping, impulses, ambient, snr_db, n_modes, channel_names :
        As for :func:`simulate_record`, the same for every test.
    tests : sequence of str, optional
        Test names; default all.
    effects : Effects or mapping of test name to Effects, optional
        Hidden effects, for all tests or per test (tests not in the
        mapping get none).
    seed : int
        Each test gets its own stream, spawned from ``SeedSequence(seed)``.
    overwrite : bool
        Replace an existing non-empty ``out_dir`` (as a whole).
    field : FieldConditions or mapping of test name to FieldConditions, optional
        Field-like disturbances (as for :func:`simulate_record`), for all
        tests or per test (tests not in the mapping get none). A test with
        any gets ``"field"`` (the parts that are on) in ``truth.json``; with
        a drift also ``"time_averaged_frequencies"`` (Hz, per mode: the
        instantaneous frequency averaged over the record's samples, the
        value an estimate should be scored against) and ``"mean_tension"``
        (its ``"tension"`` is then the tension at t = 0); with ``float32``
        the record's samples are written as float32. Without ``field`` the
        records' samples, ``campaign.toml`` and ``truth.json`` are what they
        were before this option existed.
    progress : callable(done, total), optional
        Called after each test with the number of tests done.
    directions : sequence or None
        One per position, as for :func:`simulate_record` (the records carry
        them), the same for every test.
    bridge : BridgeConditions or mapping of test name to BridgeConditions, optional
        As for :func:`simulate_record`, for all tests or per test (tests not
        in the mapping get none). With ``directions`` or ``bridge``, a
        test's entry in ``truth.json`` also has ``"frequencies_in"`` (the
        same as ``"frequencies"``), ``"frequencies_out"``,
        ``"damping_out"`` and ``"modes_out"`` (the out-of-plane modes;
        absent for a cable with dampers none of whose channels reads
        out-of-plane motion), ``"channel_directions"`` (as stated in the
        record), and with bridge conditions ``"bridge"`` (the parts that are
        on), ``"structural_frequencies"`` (Hz), ``"misalignment"`` (degrees
        per channel) and ``"traffic_crossings"`` (s, the crossings' start
        times); under a drift ``"time_averaged_frequencies_out"``.

    Returns
    -------
    Path
        ``out_dir``.

    Raises
    ------
    FileExistsError
        If ``out_dir`` is a non-empty directory (or a file) and not ``overwrite``.
    ModelError
        For an invalid option or an unknown test name.
    """
    out = Path(out_dir)
    _check_target(out, overwrite)
    check_timing(duration, sampling_rate)  # sizes before anything is allocated
    impulses = check_impulses(impulses)
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ModelError(f"must be an integer >= 0, got {seed!r}", field="seed")
    selected = _select_tests(campaign, tests)
    per_test = _effects_per_test(effects, selected)
    field_per_test = _field_per_test(field, selected)
    bridge_per_test = _per_test(bridge, selected, BridgeConditions, "bridge")
    stems = _record_stems([t.name for t in selected])
    streams = np.random.SeedSequence(seed).spawn(len(selected))
    options = {"duration": duration, "sampling_rate": sampling_rate, "damping": damping,
               "impulses": tuple(impulses), "ambient": ambient, "snr_db": snr_db, "n_modes": n_modes,
               "channel_names": channel_names, "directions": directions}
    with whole_directory(out) as tmp:
        (tmp / "records").mkdir()
        nominal_tests, truth_tests = [], []
        for i, (test, stem) in enumerate(zip(selected, stems)):
            rel = f"records/{stem}.h5"
            truth_tests.append(_simulate_test(campaign, test, tmp / rel, positions, per_test[test.name],
                                              streams[i], options, field_per_test[test.name],
                                              bridge_per_test[test.name]))
            truth_tests[-1]["record"] = rel
            nominal_tests.append(replace(test, frequencies=None, modes=None, planes=None, reference=(), record=rel))
            if progress is not None:
                progress(i + 1, len(selected))
        nominal = replace(campaign, tests=tuple(nominal_tests), directory=None)
        header = f"Simulated by stcs_ident.simulate.simulate_campaign; the true model is in {TRUTH_FILE}."
        (tmp / CAMPAIGN_FILE).write_text(campaign_to_toml(nominal, header=header), encoding="utf-8")
        truth = {"campaign": campaign.name, "options": _options_json(positions, seed, options), "tests": truth_tests}
        (tmp / TRUTH_FILE).write_text(json.dumps(truth, indent=2) + "\n", encoding="utf-8")
        _check_target(out, overwrite)  # again: the target may have changed while the records were made
    return out


def _simulate_test(campaign: Campaign, test: Test, path: Path, positions, effects: Effects | None,
                   stream: np.random.SeedSequence, options: dict, field: FieldConditions | None = None,
                   bridge: BridgeConditions | None = None) -> dict:
    attachments = campaign.setup(test.setup).attachments
    record, record_truth = simulate_record_with_truth(campaign.cable, attachments, test.tension, positions,
                                                      effects=effects, seed=stream, field=field, bridge=bridge,
                                                      **options)
    write_record_as(record, path, float32=field is not None and field.float32)
    cable, atts, tension = true_model(campaign.cable, attachments, test.tension, effects)
    damped = has_dampers(atts)
    if damped:  # the complex modes' |s|/2π, as the record holds them
        frequencies = record_truth.frequencies
    else:
        frequencies = modal_basis(cable, atts, tension, options["sampling_rate"], options["n_modes"]).frequencies
    n = len(frequencies)
    truth = {
        "name": test.name, "setup": test.setup, "stated_tension": test.tension, "tension": tension,
        "effects": effects.to_dict() if effects else {}, "effect_names": effects.names if effects else [],
        "cable": _cable_json(cable),
        "attachments": [_attachment_json(a) for a in atts],
        "modes": list(range(1, n + 1)),
        "frequencies": [float(f) for f in frequencies],
        "nominal_frequencies": [float(f) for f in natural_frequencies(campaign.cable, attachments, test.tension, n)],
        "damping": [float(z) for z in modal_damping(options["damping"], n)],
    }
    if damped:
        # "damping" above is the cable's own (intrinsic) part; the complex modes' ratios are the record's.
        truth["mode_damping"] = [float(z) for z in record_truth.damping]
    if field is not None:
        truth["field"] = field.to_dict()
        if record_truth.drifts:
            truth["time_averaged_frequencies"] = [float(f) for f in record_truth.mean_frequencies]
            truth["mean_tension"] = record_truth.mean_tension
    if options["directions"] is not None or bridge is not None:
        truth.update(_planes_json(record_truth, frequencies, bridge))
    return truth


def _planes_json(record_truth, frequencies, bridge: BridgeConditions | None) -> dict:
    """truth.json's keys of both planes and the bridge (:func:`simulate_campaign`'s ``directions``, ``bridge``)."""
    out: dict = {"frequencies_in": [float(f) for f in frequencies]}
    if record_truth.out is not None:
        f_out = record_truth.frequencies_out
        out["modes_out"] = list(range(1, len(f_out) + 1))
        out["frequencies_out"] = [float(f) for f in f_out]
        out["damping_out"] = [float(z) for z in record_truth.damping_out]
        if record_truth.out.drifts:
            out["time_averaged_frequencies_out"] = [float(f) for f in record_truth.out.mean_frequencies]
    directions = record_truth.channel_directions
    out["channel_directions"] = None if directions is None else [direction_text(d) for d in directions]
    if bridge is not None:
        out["bridge"] = bridge.to_dict()
        out["structural_frequencies"] = [float(f) for f in record_truth.structural_frequencies]
        if record_truth.misalignment is not None:
            out["misalignment"] = [float(d) for d in record_truth.misalignment]
        if record_truth.crossings is not None and bridge.traffic is not None:
            out["traffic_crossings"] = [float(t) for t in record_truth.crossings]
    return out


def _attachment_json(a: Attachment) -> dict:
    out = {"name": a.name, "position": a.position, "mass": a.mass, "stiffness": a.stiffness}
    if isinstance(a, Damper):
        out["coefficient"] = a.coefficient
    return out


def _cable_json(cable: Cable) -> dict:
    def end(b):
        return b.kind if b.kind != "spring" else b.rotational_stiffness

    return {"length": cable.length, "mass_per_length": cable.mass_per_length, "EI": cable.EI, "EA": cable.EA,
            "inclination_deg": math.degrees(cable.inclination), "gravity": cable.gravity,
            "boundary": [end(cable.boundary_a), end(cable.boundary_b)]}


def _options_json(positions, seed: int, options: dict) -> dict:
    ambient = options["ambient"]
    return {
        "positions": [float(x) for x in np.atleast_1d(positions)], "seed": seed,
        "duration": float(options["duration"]), "sampling_rate": float(options["sampling_rate"]),
        "impulses": [{"time": i.time, "position": i.position, "magnitude": i.magnitude,
                      **({} if i.direction == "in" else {"direction": direction_text(i.direction)})}
                     for i in options["impulses"]],
        "ambient": None if ambient is None else {"rms_pressure": ambient.rms_pressure,
                                                 "correlation_length": ambient.correlation_length},
        "snr_db": None if options["snr_db"] is None else float(options["snr_db"]), "n_modes": None if options["n_modes"] is None else int(options["n_modes"]),
        **({} if options["directions"] is None else {"directions": [
            direction_text(d) for d in check_channel_directions(options["directions"], len(np.atleast_1d(positions)))]}),
    }


def _select_tests(campaign: Campaign, names: Sequence[str] | None) -> list[Test]:
    if names is None:
        names = [t.name for t in campaign.tests]
    elif isinstance(names, str):
        names = [names]
    known = {t.name for t in campaign.tests}
    for name in names:
        if name not in known:
            raise ModelError(f"names no test of the campaign (known: {sorted(known)})", field=f"tests[{name}]")
    if not names:
        raise ModelError("no test to simulate", field="tests")
    return [campaign.test(name) for name in dict.fromkeys(names)]


def _effects_per_test(effects, tests: list[Test]) -> dict[str, Effects | None]:
    if effects is None or isinstance(effects, Effects):
        return {t.name: effects for t in tests}
    if not isinstance(effects, Mapping):
        raise ModelError("must be an Effects, a mapping of test name to Effects, or None", field="effects")
    unknown = set(effects) - {t.name for t in tests}
    if unknown:
        raise ModelError(f"names tests not simulated: {sorted(unknown)}", field="effects")
    return {t.name: effects.get(t.name) for t in tests}


def _per_test(value, tests: list[Test], kind: type, name: str) -> dict:
    """``value`` (one ``kind`` for all tests, a mapping of test name to one, or None) per test name."""
    if value is None or isinstance(value, kind):
        return {t.name: value for t in tests}
    if not isinstance(value, Mapping):
        raise ModelError(f"must be a {kind.__name__}, a mapping of test name to {kind.__name__}, or None", field=name)
    unknown = set(value) - {t.name for t in tests}
    if unknown:
        raise ModelError(f"names tests not simulated: {sorted(unknown)}", field=name)
    for test, one in value.items():
        if one is not None and not isinstance(one, kind):
            raise ModelError(f"must be a {kind.__name__} or None, got {type(one).__name__}", field=f"{name}[{test}]")
    return {t.name: value.get(t.name) for t in tests}


def _field_per_test(field, tests: list[Test]) -> dict[str, FieldConditions | None]:
    if field is None or isinstance(field, FieldConditions):
        return {t.name: field for t in tests}
    if not isinstance(field, Mapping):
        raise ModelError("must be a FieldConditions, a mapping of test name to FieldConditions, or None",
                         field="field")
    unknown = set(field) - {t.name for t in tests}
    if unknown:
        raise ModelError(f"names tests not simulated: {sorted(unknown)}", field="field")
    for name, value in field.items():
        if value is not None and not isinstance(value, FieldConditions):
            raise ModelError(f"must be a FieldConditions or None, got {type(value).__name__}", field=f"field[{name}]")
    return {t.name: field.get(t.name) for t in tests}


def _record_stems(names: list[str]) -> list[str]:
    """File names for test names: unsafe characters become '_'; collisions get a suffix."""
    stems, seen = [], set()
    for name in names:
        stem = re.sub(r"[^A-Za-z0-9._-]", "_", name).lstrip(".") or "test"
        base, k = stem, 2
        while stem.lower() in seen:
            stem, k = f"{base}-{k}", k + 1
        seen.add(stem.lower())
        stems.append(stem)
    return stems


def _check_target(out: Path, overwrite: bool) -> None:
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"{out}: exists and is not a directory")
    if out.is_dir() and any(out.iterdir()) and not overwrite:
        raise FileExistsError(f"{out}: directory exists and is not empty (pass overwrite=True to replace it)")
