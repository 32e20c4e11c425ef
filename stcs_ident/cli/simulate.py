"""``stcs-ident simulate``: simulated records of a campaign's tests, with optional hidden effects."""

from __future__ import annotations

import argparse
import os

from .. import effects
from ..core.errors import InputError
from .common import campaign_inputs, command_parser, progress_line
from .track import add_archive_options, check_archive_only, simulate_archive_from_args


def add_parser(sub) -> None:
    """The ``simulate`` subcommand and its options (one per registered effect that has one)."""
    sim = command_parser(sub, "simulate",
                         description="Writes OUT/campaign.toml (the nominal cable only), OUT/records/<test>.h5 "
                                     "and OUT/truth.json (the true model and frequencies).")
    sim.add_argument("campaign", help="campaign directory or its campaign.toml")
    sim.add_argument("--out", required=True, metavar="DIR", help="output directory (new or empty)")
    sim.add_argument("--test", action="append", metavar="NAME", help="only this test (repeatable)")
    sim.add_argument("--sensors", default="0.23,0.5,0.71", metavar="X,...",
                     help="sensor positions as fractions of the length (default 0.23,0.5,0.71)")
    sim.add_argument("--duration", type=float, default=60.0, metavar="S", help="record length, s (default 60)")
    sim.add_argument("--sampling-rate", type=float, default=200.0, metavar="HZ", help="default 200 Hz")
    sim.add_argument("--damping", type=float, default=0.005, metavar="ZETA", help="modal damping ratio (0.005)")
    sim.add_argument("--impulses", type=int, default=1, metavar="N",
                     help="hand-excitation events from t = 1 s, duration/N s apart (at least 1 s; default 1; "
                          "0 for none)")
    sim.add_argument("--ambient", type=float, default=None, metavar="PA",
                     help="ambient random pressure, RMS N/m per metre (default off)")
    sim.add_argument("--snr", type=float, default=30.0, metavar="DB", help="sensor noise, dB (default 30)")
    sim.add_argument("--seed", type=int, default=0, metavar="SEED",
                     help="random seed; each test gets its own stream from it (default 0)")
    sim.add_argument("--overwrite", action="store_true", help="replace a non-empty output directory")
    fld = sim.add_argument_group("field conditions (what field records carry besides the cable's response)")
    fld.add_argument("--lowpass", type=float, metavar="HZ",
                     help="colour the ambient loading with a 2nd-order low-pass at HZ (wind; needs --ambient)")
    fld.add_argument("--drift", metavar="REL[@S]",
                     help="slow tension drift within each record: a sinusoid of relative amplitude REL and "
                          "period S s (default 300); truth.json then holds the time-averaged frequencies")
    fld.add_argument("--pink-noise", type=float, metavar="REL", help="1/f sensor noise, rms relative to the signal")
    fld.add_argument("--hum", metavar="HZ:A1[,A2...]",
                     help="mains hum at HZ and its harmonics, amplitudes relative to the signal rms")
    fld.add_argument("--dc-offset", type=float, metavar="REL", help="a DC offset in every channel, relative to "
                                                                    "the signal rms")
    fld.add_argument("--float32", action="store_true", help="write single-precision samples")
    fld.add_argument("--field-random", action="store_true",
                     help="random field-like conditions per test (each part on with probability 0.75; from --seed)")
    brg = sim.add_argument_group("both planes and the bridge (what a cable on a bridge records besides its "
                                 "in-plane response; all off by default)")
    brg.add_argument("--directions", metavar="D,...",
                     help="channels per sensor position: in, out, axial or an angle in degrees (in,out: a biaxial "
                          "sensor at each position; default in)")
    brg.add_argument("--triaxial", action="store_true", help="same as --directions in,out,axial")
    brg.add_argument("--misalignment", type=float, metavar="DEG",
                     help="every sensor's true axis turned by DEG from its stated direction (planes mix)")
    brg.add_argument("--deck-modes", metavar="F:A[:END],...",
                     help="deck modes moving an anchorage: frequency F Hz, rms acceleration A m/s2, end A or B "
                          "(default B), vertical (in-plane and axial by the cable's inclination; a vertical cable's "
                          "all axial)")
    brg.add_argument("--traffic", metavar="RATE[:B]",
                     help="vehicles per hour crossing: bursts that triple the deck motion, with broadband "
                          "anchorage motion of rms B m/s2 (default 0)")
    eff = sim.add_argument_group("hidden effects (in the records, not in the written campaign)")
    for effect in effects.effects():
        if effect.option is not None:
            o = effect.option
            eff.add_argument(o.flag, dest=f"effect_{effect.name}", metavar=o.metavar,
                             action="append" if o.repeatable else "store", help=f"{effect.name}: {o.help}")
    add_archive_options(sim)


def field_options() -> dict[str, str]:
    """The option that gave each library field a refusal may name (``effects.extra_mass`` → ``--extra-mass``)."""
    hidden = {f"effects.{e.truth_key}": e.option.flag for e in effects.effects() if e.option is not None}
    return {**hidden, "excitation": "--impulses"}


def run(args: argparse.Namespace) -> int:
    """Run ``simulate``; returns the exit status."""
    from ..core.files import check_outputs
    from ..io.campaign import campaign_file, load_campaign
    from ..simulate.effects import Effects
    from ..simulate.simulate import Ambient, Impulse
    from ..simulate.simulate_campaign import simulate_campaign

    campaign = load_campaign(args.campaign)
    file = str(campaign_file(args.campaign))
    check_outputs([("--out", args.out, True)], campaign_inputs(campaign, file))
    if args.archive is not None:
        for flag, given in (("--directions", args.directions), ("--triaxial", args.triaxial or None),
                            ("--misalignment", args.misalignment), ("--deck-modes", args.deck_modes),
                            ("--traffic", args.traffic)):
            if given is not None:
                raise InputError("applies to a campaign's records, not to an archive (--archive)", field=flag)
        if os.path.exists(args.out) and os.listdir(args.out) and not args.overwrite:
            raise InputError("exists and is not empty (use --overwrite to replace it)", field="--out", file=args.out)
        return simulate_archive_from_args(args, campaign)
    check_archive_only(args)
    try:
        fractions = [float(x) for x in args.sensors.split(",")]
    except ValueError:
        raise InputError(f"expected fractions like 0.2,0.5, got {args.sensors!r}", field="--sensors") from None
    if not all(0 < x < 1 for x in fractions):
        raise InputError("fractions of the length must lie in (0, 1)", field="--sensors")
    length = campaign.cable.length
    directions = _directions(args)
    per_position = len(directions) if directions is not None else 1
    positions = [f * length for f in fractions for _ in range(per_position)]
    bridge = _bridge(args, campaign)
    hidden = {}
    for effect in effects.effects():
        given = getattr(args, f"effect_{effect.name}", None)
        if effect.option is not None and given is not None:
            hidden[effect.truth_key] = effect.parse_option(given)
    impulses = (Impulse(1.0 + i * max(args.duration / max(args.impulses, 1), 1.0), 0.17 * length, 50.0)
                for i in range(args.impulses))  # lazily: simulate refuses more than it can take
    ambient = Ambient(args.ambient) if args.ambient else None
    if os.path.exists(args.out) and os.listdir(args.out) and not args.overwrite:
        raise InputError("exists and is not empty (use --overwrite to replace it)", field="--out", file=args.out)
    effect = Effects(**hidden) if hidden else None  # a refusal names effects.<key>, shown as its option
    field = _field_conditions(args, campaign, len(positions))
    out = simulate_campaign(campaign, args.out, positions=positions,
                            directions=None if directions is None else directions * len(fractions), bridge=bridge,
                            duration=args.duration, sampling_rate=args.sampling_rate, tests=args.test,
                            damping=args.damping, impulses=impulses, ambient=ambient, snr_db=args.snr,
                            effects=effect, seed=args.seed, overwrite=args.overwrite, field=field,
                            progress=lambda k, n: progress_line(f"simulate: test {k} of {n}"))
    print(f"wrote {out}")
    return 0


def _directions(args) -> list | None:
    """The channels' directions at each sensor position (``--directions``, ``--triaxial``), or None."""
    from ..core.errors import ModelError
    from ..core.planes import check_direction

    if args.triaxial and args.directions is not None:
        raise InputError("give --directions or --triaxial, not both", field="--triaxial")
    if args.triaxial:
        return ["in", "out", "axial"]
    if args.directions is None:
        return None
    try:
        return [check_direction(d) for d in args.directions.split(",")]
    except ModelError as err:
        raise InputError(err.message, field="--directions") from None


def _bridge(args, campaign):
    """``--misalignment``, ``--deck-modes`` and ``--traffic`` as BridgeConditions, or None."""
    from ..core.errors import ModelError
    from ..simulate import BridgeConditions, StructuralMode, Traffic

    # a deck's vertical motion in the cable's frame (a vertical hanger's: all axial, exactly)
    vertical = (campaign.cable.chord_cosine, 0.0, campaign.cable.chord_sine)

    def deck_mode(text):
        parts = text.split(":")
        if len(parts) not in (2, 3):
            raise ValueError(f"expected F:A or F:A:END, got {text!r}")
        return StructuralMode(float(parts[0]), float(parts[1]), end=parts[2] if len(parts) == 3 else "B",
                              direction=vertical)

    def traffic(text):
        rate, _, broadband = text.partition(":")
        return Traffic(float(rate), broadband=float(broadband) if broadband else 0.0, direction=vertical)

    parts = {}
    try:
        flag = "--misalignment"
        if args.misalignment is not None:
            parts["misalignment"] = args.misalignment
        flag = "--deck-modes"
        if args.deck_modes is not None:
            parts["anchorage_motion"] = tuple(deck_mode(t) for t in args.deck_modes.split(","))
        flag = "--traffic"
        if args.traffic is not None:
            parts["traffic"] = traffic(args.traffic)
            if not parts.get("anchorage_motion") and parts["traffic"].broadband == 0:
                raise ValueError("swells the deck motion: give --deck-modes too, or a broadband level (RATE:B)")
        return BridgeConditions(**parts) if parts else None
    except (ValueError, ModelError) as err:
        raise InputError(" ".join(str(getattr(err, "message", err)).split()), field=flag) from None


def _field_conditions(args, campaign, n_channels: int):
    """``simulate``'s field-condition options as FieldConditions (per test with --field-random), or None."""
    import numpy as np

    from ..simulate import (
        DcOffsets,
        FieldConditions,
        LowPassLoading,
        MainsHum,
        PinkNoise,
        TensionDrift,
        random_field_conditions,
    )

    if args.field_random:
        rng = np.random.default_rng([args.seed, 17])
        return {t.name: random_field_conditions(rng, args.sampling_rate, args.duration, n_channels,
                                                ambient=args.ambient is not None) for t in campaign.tests}
    def drift(text):
        amplitude, _, period = text.partition("@")
        return TensionDrift(amplitude=float(amplitude), period=float(period) if period else 300.0)

    def hum(text):
        frequency, _, amplitudes = text.partition(":")
        return MainsHum(float(frequency), tuple(float(a) for a in amplitudes.split(",")), relative=True)

    builders = (("ambient_lowpass", "--lowpass", args.lowpass, LowPassLoading),
                ("drift", "--drift", args.drift, drift),
                ("pink_noise", "--pink-noise", args.pink_noise, lambda v: PinkNoise(v, relative=True)),
                ("hum", "--hum", args.hum, hum),
                ("dc_offsets", "--dc-offset", args.dc_offset, lambda v: DcOffsets(v, relative=True)))
    if args.lowpass is not None and args.ambient is None:
        raise InputError("colours the ambient loading: give --ambient too", field="--lowpass")
    parts = {}
    for key, flag, given, build in builders:
        if given is None:
            continue
        try:
            parts[key] = build(given)
        except ValueError as err:  # a number that does not parse, or a ModelError naming the condition's field
            raise InputError(" ".join(str(getattr(err, "message", err)).split()), field=flag) from None
    if args.float32:
        parts["float32"] = True
    return FieldConditions(**parts) if parts else None
