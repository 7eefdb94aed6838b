"""``mjstruct convert IN [-o OUT]``: a mechanism from one exchange format to another
(mechanism JSON/TOML, pyslvs expression or project, GraphML, node-link JSON), by suffix or by
``--from``/``--to``; nothing is written when the input cannot be represented."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

from mjstruct.cli.output import driver_list, emit_json, emit_text, flag_names

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism

_FORMATS = ("json", "toml", "pyslvs", "pyslvs-project", "graphml", "node-link")
#: how the success line names each format
_FORMAT_NAMES = {
    "json": "mechanism JSON",
    "toml": "mechanism TOML",
    "pyslvs": "pyslvs expression",
    "pyslvs-project": "pyslvs project",
    "graphml": "GraphML",
    "node-link": "node-link JSON",
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("input", metavar="IN", help="mechanism file to read")
    p.add_argument(
        "-o", "--output", metavar="OUT", help="file to write (default: standard output)"
    )
    p.add_argument(
        "--from",
        dest="source_format",
        choices=_FORMATS,
        help="format of IN (default: by suffix: .json .toml .pmks/.expr .pyslvs .graphml)",
    )
    p.add_argument(
        "--to",
        dest="target_format",
        choices=_FORMATS,
        help="format of OUT (default: by suffix; node-link must be named)",
    )
    p.add_argument(
        "--pin-slot",
        choices=("refuse", "block"),
        default="refuse",
        help="pyslvs RP (pin in a slot) joints: refuse them, or put a slider block in place",
    )
    p.add_argument("--drivers", metavar="J1,J2", help="driven joints of the result")
    p.add_argument("--json", action="store_true", help="print a summary object (needs -o)")


def run(args: argparse.Namespace) -> int:
    from mjstruct.errors import MechanismError
    from mjstruct.exchange.formats import format_for, read_as, render, write_as

    if args.output is None and args.target_format is None:
        raise MechanismError("--to: name the output format when there is no -o OUT")
    if args.output is None and args.json:
        raise MechanismError("--json: needs -o OUT (without it the result goes to stdout)")
    source_format = format_for(args.input, args.source_format)
    with flag_names(pin_slot="--pin-slot"):
        m = read_as(args.input, source_format, pin_slot=args.pin_slot)
    drivers = driver_list(args.drivers, m)
    if drivers is not None:
        m = m.with_drivers(drivers)
        with flag_names(drivers="--drivers"):
            _check_drivers(m)  # before anything is written: no over-driven file
    if args.output is None:
        sys.stdout.write(render(m, args.target_format))
        return 0
    target_format = write_as(m, args.output, args.target_format)
    if not args.json:
        # what was written where, in one line (the file itself holds the result)
        emit_text(
            f"wrote {args.output} ({_FORMAT_NAMES[target_format]}: {m.n} links, "
            f"{len(m.joints)} joints, from {args.input})"
        )
    if args.json:
        from mjstruct.structure.isomorphism import canonical_code

        emit_json(
            {
                "input": args.input,
                "from": source_format,
                "output": args.output,
                "to": target_format,
                "n": m.n,
                "joints": len(m.joints),
                "canonical": canonical_code(m),
            }
        )
    return 0


def _check_drivers(m: Mechanism) -> None:
    """The drivers of ``m`` checked as every command checks them.

    The generic check (pebble game) first; when it refuses a mechanism with geometry,
    its reference configuration decides (a parallelogram's redundant constraint is
    invisible to the pebble game), as for ``kinematics``.
    """
    from mjstruct.errors import MechanismError
    from mjstruct.structure.drivers import validate_drivers

    try:
        validate_drivers(m)
    except MechanismError as generic:
        if m.frame is None or any(j.at is None for j in m.joints):
            raise
        from mjstruct.kinematics.planner import plan_kinematics

        try:
            plan_kinematics(m)
        except MechanismError as special:
            # a refusal for another reason (no assembly, a group not solvable) says
            # nothing about the drivers: the generic refusal stands
            raise (special if str(special).startswith("drivers:") else generic) from None
