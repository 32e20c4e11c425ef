"""An archive of monitoring records, simulated: days of ambient records per cable, the way ``track`` hides events.

Each cable of the archive is a campaign (its cable and the setup of its first
test, whose tension is the reference). Every ``interval`` seconds a record is
simulated at the cable's tension at that time:

    H(t) = H_ref · (1 + c_θ (θ(t) − θ_ref)) · (1 + ε) · (1 + Δ · [t ≥ t_Δ])

- θ(t), the temperature, follows a daily cycle (minimum at 05:00, maximum at
  17:00) plus a slow random walk (weather), and is written in the record;
- c_θ, the relative change of tension per °C (the cable's thermal strain
  against its anchorages: a few 1e-4 to 1e-3 per °C);
- ε, a record-to-record scatter (traffic and wind on the deck: the mean
  tension during ten minutes is not the same twice), Gaussian;
- Δ, an optional lasting change from t_Δ on one cable (a broken wire, a
  slipped anchorage).

A cable whose setup holds a :class:`~stcs_ident.core.model.Damper` is
simulated with its exact complex modes, the dashpot's coefficient following
the temperature (viscous dampers stiffen in the cold) and any
:class:`~stcs_ident.simulate.damper_history.DamperChange` (a leak, a slow
loss, a seizure) of its damper: the law is in
:mod:`~stcs_ident.simulate.damper_history`. The campaign written beside the
records keeps the coefficient it gave (at the archive's mean temperature).

The excitation is ambient (wind): a random pressure along the cable with
sensor noise. ``truth.json`` beside the cables holds each record's true
tension and temperature, and the changes; a damped cable's records also
their dampers' true coefficients and the complex modes' true frequencies and
damping ratios. A cable without a damper gets the records it got before
dampers entered the archive, bit for bit.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np

from ..core.errors import ModelError
from ..core.files import whole_directory, write_atomic
from ..core.model import Campaign, Damper, real_number
from ..io.campaign_toml import campaign_to_toml
from ..io.records.hdf5 import write_record
from .damper_history import DAMPER_TEMPERATURE_COEFFICIENT, DamperChange, check_damper_changes, damper_coefficients
from .damper_history import utc_time as _utc
from .simulate import Ambient, simulate_record_with_truth

__all__ = ["ArchiveOptions", "DamperChange", "TensionChange", "simulate_archive"]


@dataclass(frozen=True)
class TensionChange:
    """A lasting relative change of one cable's tension from a time on (``change`` = after / before − 1)."""

    cable: str
    time: str
    change: float

    def __post_init__(self):
        object.__setattr__(self, "change", real_number(self.change, "tension_change.change"))
        if not -0.5 < self.change < 0.5:
            raise ModelError(f"must lie between -0.5 and 0.5, got {self.change!r}", field="tension_change.change")
        object.__setattr__(self, "time", _utc(self.time, "tension_change.time").isoformat())


@dataclass(frozen=True)
class ArchiveOptions:
    """How the records of a simulated archive are made (see the module docstring)."""

    days: float = 3.0
    interval: float = 600.0  # s between record starts
    duration: float = 60.0  # s per record
    sampling_rate: float = 100.0
    start: str = "2026-03-01T00:00:00+00:00"
    sensors: tuple[float, ...] = (0.23, 0.5, 0.71)  # fractions of the length
    temperature_mean: float = 12.0  # °C
    temperature_amplitude: float = 6.0  # °C, half the daily swing
    thermal_coefficient: float = -5e-4  # relative tension change per °C
    scatter: float = 1e-3  # relative record-to-record scatter of the tension
    rms_pressure: float = 20.0  # N/m, the wind
    snr_db: float = 30.0
    damping: float = 0.005
    #: Per °C: a damper's coefficient is c_ref · exp(−a (θ − temperature_mean)); 0: constant
    #: (:mod:`~stcs_ident.simulate.damper_history`).
    damper_temperature_coefficient: float = DAMPER_TEMPERATURE_COEFFICIENT

    def __post_init__(self):
        for name in ("days", "interval", "duration", "sampling_rate", "rms_pressure"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"archive.{name}", positive=True))
        for name in ("temperature_mean", "temperature_amplitude", "thermal_coefficient", "scatter", "snr_db"):
            object.__setattr__(self, name, real_number(getattr(self, name), f"archive.{name}"))
        a = real_number(self.damper_temperature_coefficient, "archive.damper_temperature_coefficient")
        if not 0 <= a <= 0.1:
            raise ModelError(f"must lie between 0 and 0.1 per °C (viscous dampers stiffen in the cold; silicone oil "
                             f"about 0.015), got {a!r}", field="archive.damper_temperature_coefficient")
        object.__setattr__(self, "damper_temperature_coefficient", a)
        if self.duration > self.interval:
            raise ModelError("a record cannot last longer than the interval between records", field="archive.duration")
        object.__setattr__(self, "start", _utc(self.start, "archive.start").isoformat())

    @property
    def n_records(self) -> int:
        return int(self.days * 86400.0 // self.interval)


def simulate_archive(campaigns: Mapping[str, Campaign], out: str | os.PathLike, *,
                     options: ArchiveOptions | None = None, change: TensionChange | None = None,
                     damper_changes: Sequence[DamperChange] = (), seed: int = 0, workers: int = 1,
                     progress: Callable[[int, int], None] | None = None) -> Path:
    """Write an archive ``out/<cable>/{campaign.toml, records/<day>/<cable>_<time>.h5}`` and ``out/truth.json``.

    Parameters
    ----------
    campaigns : mapping of cable name to Campaign
        Each needs a test: its setup and tension are the cable's (the reference).
    options : ArchiveOptions
    change : TensionChange or None
        A lasting change of one cable's tension.
    damper_changes : sequence of DamperChange
        Leaks, slow losses and seizures of the cables' dampers (each cable named must have a damper); they
        may come with ``change`` and with each other (on one damper, their factors multiply).
    seed : int
        The same seed gives the same archive, whatever ``workers``.
    workers : int
        Local processes simulating the records (each record has its own random stream).
    progress : callable(done, total), optional

    Returns
    -------
    Path of the archive, written whole or not at all.
    """
    if change is not None and change.cable not in campaigns:
        raise ModelError(f"no cable named {change.cable!r} (cables: {', '.join(campaigns)})",
                         field="tension_change.cable")
    for name, campaign in campaigns.items():
        if not campaign.tests:
            raise ModelError("needs a test: its setup and tension are the cable's reference", field=f"cable[{name}]")
    damper_changes = check_damper_changes(damper_changes, {name: c.setup(c.tests[0].setup).attachments
                                                           for name, c in campaigns.items()})
    options = ArchiveOptions() if options is None else options
    out = Path(out)
    start = datetime.fromisoformat(options.start)
    times = [start + timedelta(seconds=k * options.interval) for k in range(options.n_records)]
    truth: dict = {"options": _asdict(options), "change": None if change is None else _asdict(change),
                   "damper_changes": [_asdict(c) for c in damper_changes], "cables": {}}
    with whole_directory(out) as tmp:
        jobs = []
        for index, (name, campaign) in enumerate(campaigns.items()):
            (tmp / name / "records").mkdir(parents=True)
            write_atomic(tmp / name / "campaign.toml", campaign_to_toml(campaign, header=f"cable {name} of a "
                                                                                          "simulated archive"))
            jobs += _plan(name, index, campaign, times, options, change, damper_changes, seed)
            truth["cables"][name] = {"reference_tension": float(campaign.tests[0].tension), "records": []}
            attachments = campaign.setup(campaign.tests[0].setup).attachments
            if any(isinstance(a, Damper) for a in attachments):
                truth["cables"][name]["reference_coefficients"] = {a.name: a.coefficient for a in attachments
                                                                   if isinstance(a, Damper)}
        for done, (name, row) in enumerate(_map(_simulate_one, [(tmp, job) for job in jobs], workers), 1):
            truth["cables"][name]["records"].append(row)
            if progress is not None:
                progress(done, len(jobs))
        write_atomic(tmp / "truth.json", json.dumps(truth, indent=1) + "\n")
    return out


@dataclass(frozen=True)
class _Job:
    """One record to simulate: its cable, true configuration and random stream."""

    name: str
    campaign: Campaign
    attachments: tuple
    time: datetime
    temperature: float
    tension: float
    coefficients: dict | None  # the dampers' true coefficients; None: no damper
    options: ArchiveOptions
    seed: list


def _plan(name, index, campaign, times, options, change, damper_changes, seed) -> list[_Job]:
    """The cable's records in time order: temperature, tension and dampers drawn here, in this order, so
    that the archive does not depend on how its records are shared among workers."""
    rng = np.random.default_rng([seed, index])
    temperature = _temperatures(times, options, rng)
    reference = float(campaign.tests[0].tension)
    attachments = campaign.setup(campaign.tests[0].setup).attachments
    damped = any(isinstance(a, Damper) for a in attachments)
    jobs = []
    for k, (time, theta) in enumerate(zip(times, temperature)):
        tension = reference * (1 + options.thermal_coefficient * (theta - options.temperature_mean))
        tension *= 1 + options.scatter * rng.standard_normal()
        if change is not None and change.cable == name and time >= datetime.fromisoformat(change.time):
            tension *= 1 + change.change
        atts, coefficients = attachments, None
        if damped:  # the dashpots at this time and temperature; a cable without one is as it was
            coefficients = damper_coefficients(name, attachments, time, float(theta),
                                               temperature_coefficient=options.damper_temperature_coefficient,
                                               reference_temperature=options.temperature_mean,
                                               changes=damper_changes)
            atts = tuple(_with(a, coefficient=coefficients[a.name]) if isinstance(a, Damper) else a
                         for a in attachments)
        jobs.append(_Job(name, campaign, tuple(atts), time, float(theta), tension, coefficients, options,
                         [seed, index, k]))
    return jobs


def _simulate_one(task: tuple[Path, _Job]) -> tuple[str, dict]:
    """Simulate and write one record; (cable, its row of truth.json)."""
    root, job = task
    options, cable = job.options, job.campaign.cable
    positions = [f * cable.length for f in options.sensors]
    record, record_truth = simulate_record_with_truth(
        cable, job.attachments, job.tension, positions, duration=options.duration,
        sampling_rate=options.sampling_rate, damping=options.damping, ambient=Ambient(options.rms_pressure),
        snr_db=options.snr_db, seed=job.seed)
    record = _with(record, start_time=job.time.isoformat(), temperature=round(job.temperature, 3))
    relative = f"records/{job.time.strftime('%Y-%m-%d')}/{job.name}_{job.time.strftime('%Y%m%dT%H%M%S')}.h5"
    (root / job.name / relative).parent.mkdir(exist_ok=True)
    write_record(record, root / job.name / relative)
    row = {"record": relative, "start_time": job.time.isoformat(), "tension": job.tension,
           "temperature": job.temperature}
    if job.coefficients is not None:
        row |= {"coefficients": job.coefficients, "frequencies": record_truth.frequencies.tolist(),
                "damping": record_truth.damping.tolist()}
    return job.name, row


def _map(fn, items: list, workers: int):
    """``fn`` over ``items`` in order, on ``workers`` local processes when more than one is useful."""
    workers = max(1, int(workers))
    if workers == 1 or len(items) < 2:
        yield from map(fn, items)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    with ProcessPoolExecutor(min(workers, len(items)), mp_context=context, initializer=_one_blas_thread) as pool:
        yield from pool.map(fn, items, chunksize=max(1, min(16, len(items) // (8 * workers))))


def _one_blas_thread() -> None:
    """In each worker: BLAS on one thread. Workers each running BLAS's threads on the same cores wait for each
    other (measured, 2 workers on 2 cores, 10-minute damped records at 100 Hz: 0.27 records/s with BLAS's
    threads, 2.7 with one each)."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1)


def _temperatures(times: Sequence[datetime], options: ArchiveOptions, rng: np.random.Generator) -> np.ndarray:
    """Daily cycle (minimum at 05:00, maximum at 17:00 UTC) plus a slow random walk of the weather."""
    hours = np.array([t.hour + t.minute / 60 + t.second / 3600 for t in times])
    cycle = -np.cos(2 * np.pi * (hours - 5.0) / 24.0)
    steps = rng.standard_normal(len(times)) * 0.05 * np.sqrt(options.interval / 600.0)
    weather = np.cumsum(steps)
    return options.temperature_mean + options.temperature_amplitude * cycle + weather - weather.mean()


def _with(record, **changes):
    from dataclasses import replace

    return replace(record, **changes)


def _asdict(obj) -> dict:
    from dataclasses import asdict

    return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(obj).items()}
