"""``mjstruct kinematics FILE``: positions, velocities, accelerations over one cycle."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TypeVar

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
    checks = p.add_mutually_exclusive_group()
    checks.add_argument(
        "--no-checks",
        action="store_true",
        help="skip the checks; by default only those that cost O(frames) run: "
        "near-singular frames from the plan's determinants, closure residuals, link "
        "lengths, analogs vs differences",
    )
    checks.add_argument(
        "--full-checks",
        action="store_true",
        help="also check the constraint Jacobian: its rank (redundant constraints, DOF) "
        "and its determinant with the drivers fixed (dense matrices on a few frames)",
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


T = TypeVar("T")


def _write(write: Callable[[], T], path: str) -> T:
    """Run ``write``; a file system error is bad input naming ``--csv``."""
    try:
        return write()
    except OSError as exc:
        raise MechanismError(f"--csv: cannot write {path} ({exc.strerror})") from None


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.memory import CHUNK_FRAMES, Checks, check_sweep_memory
    from mjstruct.kinematics.model import KinematicModel
    from mjstruct.kinematics.report import render, render_stream, write_csv, write_csv_chunks
    from mjstruct.kinematics.solver import MAX_STROKE, kinematic_analysis, sweep_chunks
    from mjstruct.kinematics.tolerances import TOL_FLOOR

    if args.frames < 1:
        raise MechanismError(f"--frames: must be >= 1, got {args.frames}")
    if not math.isfinite(args.speed) or args.speed == 0:
        raise MechanismError(f"--speed: must be a finite nonzero number, got {args.speed}")
    # a slide of |stroke| × frames (and its square, in the triangles) must be a double
    if not math.isfinite(args.stroke) or not abs(args.stroke) <= MAX_STROKE:
        raise MechanismError(
            f"--stroke: must be a finite number of at most {MAX_STROKE:g} in size, "
            f"got {args.stroke:g}"
        )
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
    checks: Checks = "full" if args.full_checks else not args.no_checks
    with flag_names(**FLAGS):
        model = KinematicModel.build(m, drivers)
        if args.csv and not args.json and args.frames > CHUNK_FRAMES:
            # the table alone: solved and written chunk by chunk, in bounded memory
            chunks = sweep_chunks(
                model,
                args.frames,
                speed=args.speed,
                stroke=args.stroke,
                tol=args.tol,
                checks=checks,
                chunk=CHUNK_FRAMES,
                max_memory=args.max_memory,
            )
            summary = _write(lambda: write_csv_chunks(chunks, args.csv), args.csv)
            emit_text(render_stream(summary, args.csv))
            return 0
        if args.json:
            # the JSON text is the largest output: estimated on its own
            check_sweep_memory(model, args.frames, args.max_memory, output="json", checks=checks)
        r = kinematic_analysis(
            model,
            frames=args.frames,
            speed=args.speed,
            stroke=args.stroke,
            tol=args.tol,
            checks=checks,
            max_memory=args.max_memory,
        )
    if args.csv:
        _write(lambda: write_csv(r, args.csv), args.csv)
    if args.json:
        emit_json(r.to_dict())
    else:
        text = render(r)
        if args.csv:  # as draw, plot and animate say what they wrote
            text += f"\nwrote {args.csv} (the table: {args.frames} frames, one row each)"
        emit_text(text)
    return 0
