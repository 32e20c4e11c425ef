"""``stcs-ident tension``: the quick answer, a tension from a length, a mass and frequencies or one record (no
campaign file)."""

from __future__ import annotations

import argparse
import sys

from ..core.errors import InputError
from .common import add_json_option, command_parser, to_json, write_output
from .reader_options import add_reader_options, as_options, reading_from_args


def add_parser(sub) -> None:
    """The ``tension`` subcommand and its options."""
    parser = command_parser(sub, "tension")
    parser.add_argument("--length", required=True, metavar="L", help="chord length between the anchorages, m")
    parser.add_argument("--mass", required=True, metavar="M", help="mass per unit length, kg/m")
    given = parser.add_mutually_exclusive_group(required=True)
    given.add_argument("--frequencies", metavar="F1[,F2,...]", help="measured frequencies, Hz")
    given.add_argument("--record", metavar="FILE", help="an acceleration record (any format spectra reads): its peaks "
                                                         "picked and numbered from their own spacing")
    parser.add_argument("--modes", metavar="1,2,...", help="their mode numbers (default 1, 2, ...)")
    parser.add_argument("--EI", metavar="N_M2", help="bending stiffness, N m^2, known to --EI-tolerance: with one "
                                                     "mode held, with more a prior of the fit (default: fitted with "
                                                     "two modes or more; with one mode the answer is a range)")
    parser.add_argument("--EA", metavar="N", help="axial stiffness, N, for sag-extensibility (default: ignored)")
    parser.add_argument("--inclination", default="0", metavar="DEG", help="chord angle from horizontal, degrees")
    parser.add_argument("--boundary", choices=("clamped", "pinned"), default="clamped", help="both ends")
    parser.add_argument("--plane", choices=("in", "out"), default="in",
                        help="plane of the measured modes: in (in-plane, with sag-extensibility when --EA is given) "
                             "or out (out-of-plane: no sag-extensibility, --EA unused); default in")
    parser.add_argument("--uncertainty", metavar="HZ", help="1σ of the frequencies, Hz, one for all or one each "
                                                            "(default: their printed rounding / sqrt 12)")
    parser.add_argument("--EI-tolerance", metavar="REL", help="relative 1σ of a given --EI: carried into the σ "
                                                              "with one mode, the prior's width with more "
                                                              "(default 0.3; 0: exact, held)")
    parser.add_argument("--length-tolerance", metavar="REL", help="relative 1σ of --length (default 0.002)")
    parser.add_argument("--mass-tolerance", metavar="REL", help="relative 1σ of --mass (default 0.01)")
    add_reader_options(parser, "--record")
    add_json_option(parser)


def _number(text: str | None, option: str) -> float | None:
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        raise InputError(f"must be a number, got {text!r}", field=option) from None


def _numbers(text: str | None, option: str, kind=float) -> list | None:
    if text is None:
        return None
    items = [t.strip() for t in text.split(",")]
    try:
        return [kind(t) for t in items]
    except ValueError:
        what = "integers" if kind is int else "numbers"
        raise InputError(f"must be comma-separated {what}, got {text!r}", field=option) from None


def field_options() -> dict[str, str]:
    """The library's argument names that are not the option's name."""
    return {"mass": "--mass", "EI": "--EI", "EA": "--EA", "EI_tolerance": "--EI-tolerance",
            "length_tolerance": "--length-tolerance", "mass_tolerance": "--mass-tolerance",
            "mass_per_length_tolerance": "--mass-tolerance"}


def force_unit(values) -> tuple[str, float]:
    """N, kN or MN by the largest magnitude among ``values`` (N), and its factor."""
    size = max((abs(v) for v in values if v is not None), default=0.0)
    return next(((unit, f) for unit, f in (("MN", 1e6), ("kN", 1e3)) if size >= f), ("N", 1.0))


def tension_text(result) -> str:
    """The table of the methods that give a tension (a range for the exact model with EI unknown and one mode),
    the exact model's EI and other end condition, one line naming the methods left out, then the notes."""
    inputs = result.inputs
    sigma = inputs["uncertainty"]
    sigma_text = f"{sigma[0]:.3g} Hz" if len(set(sigma)) == 1 else ", ".join(f"{s:.3g}" for s in sigma) + " Hz"
    k = len(inputs["modes"])
    lines = [(f"length {inputs['length']:g} m, mass {inputs['mass']:g} kg/m, mode{'s' if k > 1 else ''} "
              f"{', '.join(map(str, inputs['modes']))}, {inputs['boundary']} ends, inclination "
              f"{inputs['inclination']:g} deg" + (", out-of-plane modes" if inputs.get("plane") == "out" else "")),
             f"frequency 1σ: {sigma_text}, {inputs['uncertainty_source']}", ""]
    methods = result.methods
    exact = methods["exact"]
    shown = [m.tension for m in methods.values()] + [exact.extra.get("upper")]
    unit, factor = force_unit(shown)
    lines.append(f"{'method':<13} {f'tension ({unit})':>16} {f'1σ ({unit})':>10}")
    left = []
    for name, m in methods.items():
        if m.tension is not None:
            lines.append(f"{name:<13} {m.tension / factor:>16.6g} {m.uncertainty / factor:>10.3g}")
        elif name == "exact" and m.extra.get("upper") is not None:
            span = f"{m.extra['lower'] / factor:.4g} to {m.extra['upper'] / factor:.4g}"
            lines.append(f"{name:<13} {span:>16} {'(range)':>10}")
        elif name != "mehrabi1998":
            left.append(name)
    EI_source = exact.extra.get("EI_source")
    if exact.tension is not None and EI_source:
        EI, EIs = exact.extra.get("EI"), exact.extra.get("EI_uncertainty")
        shown_EI = "0" if EI is None else f"{EI:.4g}" + (f" ± {EIs:.2g}" if EIs is not None else "")
        lines.append(f"exact model's EI: {shown_EI} N m^2, {EI_source}")
    other = exact.extra.get("other_boundary", {})
    if other.get("note"):
        lines.append(f"exact model {other['note']}")
    if left:
        lines.append("left out: " + "; ".join(f"{name} ({methods[name].note})" for name in left))
    notes = [f"  {name}: {m.note}" for name, m in methods.items()
             if m.note and m.tension is not None or (name == "exact" and m.note and name not in left)]
    if notes:
        lines += ["", "notes:"] + notes
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    """Run ``tension``; returns the exit status (1 when the exact model's fit failed)."""
    from ..identify.quick import quick_tension, rounding_uncertainty

    reading = reading_from_args(args, args.record is not None, "--record")
    if args.record is not None:
        return _run_record(args, reading)
    frequencies = _numbers(args.frequencies, "--frequencies")
    uncertainty = _numbers(args.uncertainty, "--uncertainty")
    source = "stated (--uncertainty)" if uncertainty is not None else None
    if uncertainty is None:
        sigma, source = rounding_uncertainty(args.frequencies.split(","))
        uncertainty = [sigma]
    result = quick_tension(_number(args.length, "--length"), _number(args.mass, "--mass"), frequencies,
                           _numbers(args.modes, "--modes", int), EI=_number(args.EI, "--EI"),
                           EA=_number(args.EA, "--EA"), inclination=_number(args.inclination, "--inclination"),
                           boundary=args.boundary, uncertainty=uncertainty if len(uncertainty) > 1 else uncertainty[0],
                           uncertainty_source=source, EI_tolerance=_number(args.EI_tolerance, "--EI-tolerance"),
                           length_tolerance=_number(args.length_tolerance, "--length-tolerance"),
                           mass_tolerance=_number(args.mass_tolerance, "--mass-tolerance"), plane=args.plane)
    if args.json:

        write_output(args.json, to_json(result.summary()))
    if args.json != "-":
        sys.stdout.write(tension_text(result))
    return 1 if result.methods["exact"].failed else 0


def _run_record(args: argparse.Namespace, reading) -> int:
    """``tension --record``: the record's peaks, numbered from their spacing, then every method."""
    from ..identify.quick_record import tension_from_record

    for option in ("--modes", "--uncertainty"):
        if getattr(args, option[2:]) is not None:
            raise InputError("goes with --frequencies: with --record the peaks' numbers and 1σ come from the record",
                             field=option)
    try:
        result = tension_from_record(args.record, _number(args.length, "--length"), _number(args.mass, "--mass"),
                                     reading=reading, EI=_number(args.EI, "--EI"), EA=_number(args.EA, "--EA"),
                                     inclination=_number(args.inclination, "--inclination"), boundary=args.boundary,
                                     plane=args.plane, EI_tolerance=_number(args.EI_tolerance, "--EI-tolerance"),
                                     length_tolerance=_number(args.length_tolerance, "--length-tolerance"),
                                     mass_tolerance=_number(args.mass_tolerance, "--mass-tolerance"))
    except InputError as err:  # a reader's fix said as the option to type
        raise as_options(err) from None
    if args.json:
        write_output(args.json, to_json(result.summary()))
    if args.json != "-":
        sys.stdout.write(record_text(result) + tension_text(result.tension))
    return 1 if result.methods["exact"].failed else 0


def record_text(result) -> str:
    """The record read and its peaks, numbered from their own harmonic series."""
    rec = result.record
    lines = [(f"record {rec['path']}: {rec['kind']}, {rec['duration']:.4g} s at {rec['sampling_rate']:.6g} Hz, "
              f"channels {', '.join(rec['channels'])}")]
    lines += [f"  {o['option']}: {o['given']} given, the file's {o['file']}" for o in rec["replaced"]]
    lines += [f"  dropped {d['channel']}: {d['reason']}" for d in rec["dropped"]]
    lines += [f"  note: {n}" for n in rec["notes"]]
    series = result.series
    lines.append(f"peaks numbered from their own spacing: f_n = n x {series.fundamental:.5g} Hz x sqrt(1 + "
                 f"{series.inharmonicity:.3g} n^2), {series.n_assigned} of {len(result.peaks)} peaks")
    lines.append(f"{'mode':>5} {'frequency':>11} {'1σ (Hz)':>10}")
    for p in sorted((p for p in result.peaks if p["mode"] is not None), key=lambda p: p["mode"]):
        lines.append(f"{p['mode']:>5} {p['frequency']:>11.5f} {p['uncertainty']:>10.2g}")
    lines += [f"  {n}" for n in result.notes]
    return "\n".join(lines) + "\n\n"
