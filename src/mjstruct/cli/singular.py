"""``mjstruct singular FILE``: input limits, output extremes, change points, clearance zones."""

from __future__ import annotations

import argparse
import math

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="one-DOF mechanism file with geometry (.json or .toml)")
    p.add_argument(
        "--clearance",
        type=float,
        metavar="D",
        help="total radial clearance of the pins (file's length unit): adds the zones",
    )
    p.add_argument("--output", metavar="LINK", help="output link (default: see the contract)")
    p.add_argument(
        "--exact", action="store_true", help="also compute each zone by a feasibility search"
    )
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.singular import singular_analysis
    from mjstruct.kinematics.tolerances import MAX_CLEARANCE

    if args.clearance is not None and not (math.isfinite(args.clearance) and args.clearance >= 0):
        raise MechanismError(f"--clearance: must be a finite number >= 0, got {args.clearance}")
    if args.clearance is not None and args.clearance > MAX_CLEARANCE:
        # the zone formulas square (r + D): beyond this the square overflows a double
        raise MechanismError(
            f"--clearance: {args.clearance:g} is too large (at most {MAX_CLEARANCE:g})"
        )
    if args.exact and args.clearance is None:
        raise MechanismError("--exact: needs --clearance")
    m = read_mechanism(args.file)
    with flag_names(output="--output", clearance="--clearance"):
        r = singular_analysis(m, output=args.output, clearance=args.clearance, exact=args.exact)
    if args.json:
        emit_json(r.to_dict())
    else:
        from mjstruct.kinematics.singular import render

        emit_text(render(r))
    return 0
