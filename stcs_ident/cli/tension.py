"""``stcs-ident tension``: the quick answer, a tension from a length, a mass and frequencies (no campaign file)."""

from __future__ import annotations

import argparse
import sys

from ..core.errors import InputError
from .common import add_json_option, command_parser, write_output


def add_parser(sub) -> None:
    """The ``tension`` subcommand and its options."""
    parser = command_parser(sub, "tension")
    parser.add_argument("--length", required=True, metavar="L", help="chord length between the anchorages, m")
    parser.add_argument("--mass", required=True, metavar="M", help="mass per unit length, kg/m")
    parser.add_argument("--frequencies", required=True, metavar="F1[,F2,...]", help="measured frequencies, Hz")
    parser.add_argument("--modes", metavar="1,2,...", help="their mode numbers (default 1, 2, ...)")
    parser.add_argument("--EI", metavar="N_M2", help="bending stiffness, N m^2 (default: fitted with two modes "
                                                     "or more, else 0)")
    parser.add_argument("--EA", metavar="N", help="axial stiffness, N, for sag-extensibility (default: ignored)")
    parser.add_argument("--inclination", default="0", metavar="DEG", help="chord angle from horizontal, degrees")
    parser.add_argument("--boundary", choices=("clamped", "pinned"), default="clamped", help="both ends")
    parser.add_argument("--plane", choices=("in", "out"), default="in",
                        help="plane of the measured modes: in (in-plane, with sag-extensibility when --EA is given) "
                             "or out (out-of-plane: no sag-extensibility, --EA unused); default in")
    parser.add_argument("--uncertainty", metavar="HZ", help="1σ of the frequencies, Hz, one for all or one each "
                                                            "(default: their printed rounding / sqrt 12)")
    parser.add_argument("--EI-tolerance", metavar="REL", help="relative 1σ of a given --EI, carried into the "
                                                              "exact model's σ (default 0.3; 0: exact)")
    parser.add_argument("--length-tolerance", metavar="REL", help="relative 1σ of --length (default 0.002)")
    parser.add_argument("--mass-tolerance", metavar="REL", help="relative 1σ of --mass (default 0.01)")
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


def tension_text(result) -> str:
    """The table of methods, then each method's note."""
    inputs = result.inputs
    sigma = inputs["uncertainty"]
    sigma_text = f"{sigma[0]:.3g} Hz" if len(set(sigma)) == 1 else ", ".join(f"{s:.3g}" for s in sigma) + " Hz"
    lines = [(f"length {inputs['length']:g} m, mass {inputs['mass']:g} kg/m, modes "
              f"{', '.join(map(str, inputs['modes']))}, {inputs['boundary']} ends, inclination "
              f"{inputs['inclination']:g} deg" + (", out-of-plane modes" if inputs.get("plane") == "out" else "")),
             f"frequency 1σ: {sigma_text}, {inputs['uncertainty_source']}",
             "",
             f"{'method':<13} {'tension (kN)':>14} {'1σ (kN)':>10}"]
    for name, m in result.methods.items():
        if m.tension is None:
            lines.append(f"{name:<13} {'-':>14} {'-':>10}")
        else:
            lines.append(f"{name:<13} {m.tension / 1e3:>14.6g} {m.uncertainty / 1e3:>10.3g}")
    exact = result.methods["exact"]
    if exact.extra.get("EI_source"):
        EI, EIs = exact.extra.get("EI"), exact.extra.get("EI_uncertainty")
        shown = "0" if EI is None else f"{EI:.4g}" + (f" ± {EIs:.2g}" if EIs is not None else "")
        lines.append(f"exact model's EI: {shown} N m^2, {exact.extra['EI_source']}")
    notes = [f"  {name}: {m.note}" for name, m in result.methods.items() if m.note]
    if notes:
        lines += ["", "notes:"] + notes
    return "\n".join(lines) + "\n"


def run(args: argparse.Namespace) -> int:
    """Run ``tension``; returns the exit status (1 when the exact model's fit failed)."""
    from ..identify.quick import quick_tension, rounding_uncertainty
    from ..report.forward import to_json

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
