"""``mjstruct kinematics FILE``: positions, velocities, accelerations over one cycle."""

from __future__ import annotations

import argparse
import math

from mjstruct.cli.output import driver_list, emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="mechanism file with geometry (.json or .toml)")
    p.add_argument("--drivers", help="generalised coordinates J1,J2 (default: the file's)")
    p.add_argument("--frames", type=int, default=360, help="frames over one cycle (default 360)")
    p.add_argument(
        "--speed", type=float, default=1.0, help="constant driver speed W (rad/s; default 1)"
    )
    p.add_argument(
        "--stroke", type=float, default=1.0, help="sweep of a prismatic driver (default 1)"
    )
    p.add_argument(
        "--tol",
        type=float,
        default=1e-12,
        help="closure tolerance, relative to the mechanism's size (default 1e-12, at least 1e-15)",
    )
    p.add_argument(
        "--max-memory",
        type=int,
        metavar="BYTES",
        help="refuse sweeps estimated above this (default $MJSTRUCT_MAX_MEMORY_BYTES or 2 GiB)",
    )
    p.add_argument(
        "--no-checks",
        action="store_true",
        help="skip the checks (link lengths, analogs vs differences, Jacobian rank/det)",
    )
    p.add_argument("--csv", metavar="OUT", help="write the table (q, x y vx vy ax ay, ...) here")
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


#: the library's parameter names and the flags that set them
FLAGS = {
    "drivers": "--drivers",
    "speed": "--speed",
    "frames": "--frames",
    "tol": "--tol",
    "stroke": "--stroke",
    "max_memory": "--max-memory",
}


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.report import render, write_csv
    from mjstruct.kinematics.solver import kinematic_analysis
    from mjstruct.kinematics.tolerances import TOL_FLOOR

    if args.frames < 1:
        raise MechanismError(f"--frames: must be >= 1, got {args.frames}")
    if not math.isfinite(args.speed) or args.speed == 0:
        raise MechanismError(f"--speed: must be a finite nonzero number, got {args.speed}")
    if not math.isfinite(args.stroke):
        raise MechanismError(f"--stroke: must be a finite number, got {args.stroke}")
    if not TOL_FLOOR <= args.tol < 1:
        raise MechanismError(
            f"--tol: must be in [{TOL_FLOOR:g}, 1) (relative to the mechanism's size), "
            f"got {args.tol:g}"
        )
    if args.max_memory is not None and args.max_memory <= 0:
        raise MechanismError(
            f"--max-memory: must be a positive number of bytes, got {args.max_memory}"
        )
    m = read_mechanism(args.file)
    drivers = driver_list(args.drivers, m)
    with flag_names(**FLAGS):
        r = kinematic_analysis(
            m,
            drivers=drivers,
            frames=args.frames,
            speed=args.speed,
            stroke=args.stroke,
            tol=args.tol,
            checks=not args.no_checks,
            max_memory=args.max_memory,
        )
    if args.csv:
        try:
            write_csv(r, args.csv)
        except OSError as exc:
            raise MechanismError(f"--csv: cannot write {args.csv} ({exc.strerror})") from None
    if args.json:
        emit_json(r.to_dict())
    else:
        emit_text(render(r))
    return 0
