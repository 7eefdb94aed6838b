"""``mjstruct assur FILE [--drivers J1,J2] [--all-choices]``: Assur-group decomposition.

Prints the contract's ``groups`` (each with ``links``, ``joints``, ``class``,
``order``, plus ``external``, ``internal``, ``reference``, ``bodies``, ``within``) and
``mechanism_class``; ``--all-choices`` adds ``choices``: every choice of driven joints
(frame joints, or all joints with ``--any-joint``), admissible ones lowest class first.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from mjstruct.cli.output import driver_list, emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.structure.assur import DriverChoice


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="mechanism file (.json or .toml)")
    p.add_argument("--drivers", help="driven joint ids, comma-separated (overrides the file's)")
    p.add_argument(
        "--all-choices",
        action="store_true",
        help="list every choice of driven joints with its groups and class",
    )
    p.add_argument(
        "--any-joint",
        action="store_true",
        help="with --all-choices: any joint may be driven, not only frame joints",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")


def _choices_text(choices: list[DriverChoice]) -> str:
    from mjstruct.structure.assur import roman

    lines = ["", "Driver choices (admissible first, lowest class first):"]
    for c in choices:
        drivers = ", ".join(c.drivers) or "(none)"
        if c.decomposition is not None:  # status "ok"
            d = c.decomposition
            groups = "; ".join(f"{roman(g.klass)}({','.join(g.links)})" for g in d.groups)
            lines.append(f"  {drivers}: class {roman(d.mechanism_class)} - groups {groups}")
        else:
            detail = []
            if c.dof_left:
                detail.append(f"{c.dof_left} DOF left")
            if c.redundant:
                detail.append(f"{c.redundant} redundant")
            lines.append(f"  {drivers}: {c.status} ({', '.join(detail)})")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.structure.assur import assur_groups, driver_choices

    if args.any_joint and not args.all_choices:
        raise MechanismError("--any-joint goes with --all-choices")
    m = read_mechanism(args.file)
    if "gears" in m.extra:  # Assur groups of the equivalent lower-pair chain
        from mjstruct.gears.structure import equivalent_chain

        m = equivalent_chain(m)
    drivers = driver_list(args.drivers, m)
    if not args.all_choices and not (drivers or m.drivers):
        raise MechanismError(
            "drivers: the file names no drivers; give --drivers J1,J2 or --all-choices"
        )
    out: dict[str, Any] = {}
    text = ""
    choices = None
    if args.all_choices:
        with flag_names(limit="--all-choices"):
            choices = driver_choices(
                m.with_drivers(drivers or m.drivers), any_joint=args.any_joint
            )
    if drivers is not None or m.drivers or not choices:
        with flag_names(**({"drivers": "--drivers"} if drivers is not None else {})):
            d = assur_groups(m, drivers)
        out = d.to_dict()
        text = d.render()
    else:  # no drivers given: report the best admissible choice
        best = next((c for c in choices if c.decomposition is not None), None)
        if best is None or best.decomposition is None:
            raise MechanismError("drivers: no admissible choice of driven joints")
        out = best.decomposition.to_dict()
        text = best.decomposition.render()
    if choices is not None:
        out["choices"] = [c.to_dict() for c in choices]
        text += "\n" + _choices_text(choices)
    if args.json:
        emit_json(out)
    else:
        emit_text(text)
    return 0
