"""``mjstruct dynamics FILE``: inverse dynamics at constant speed, free one-DOF motion
(the equation of motion integrated in q), or motion in time (``--time T``)."""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

from mjstruct.cli.output import driver_list, emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism

DEFAULT_FRAMES = 360
#: output times of --time when --frames is not given
DEFAULT_TIMES = 201

#: the flag of each parameter of :func:`~mjstruct.dynamics.analysis.dynamic_analysis`
FLAGS = {
    "speed": "--speed",
    "qdot0": "--qdot0",
    "frames": "--frames",
    "drivers": "--drivers",
    "method": "--method",
    "n": "--n",
    "harmonics": "--harmonics",
    "max_memory": "--max-memory",
}

#: the flag of each parameter of :func:`~mjstruct.dynamics.time.motion_in_time`
TIME_FLAGS = {
    "t_end": "--time",
    "frames": "--frames",
    "qdot0": "--start-speed",
    "method": "--solver",
    "rtol": "--rtol",
    "drivers": "--drivers",
    "max_evaluations": "--max-evaluations",
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="mechanism file with geometry and dynamics keys (.json or .toml)")
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--speed", type=float, metavar="W", help="every driver at constant speed W")
    mode.add_argument(
        "--qdot0", type=float, metavar="W0", help="free motion under the loads from speed W0"
    )
    mode.add_argument(
        "--time", type=float, metavar="T", help="motion in time from t = 0 to T (one driver)"
    )
    p.add_argument(
        "--frames",
        type=int,
        default=None,
        help=f"frames over one cycle (default {DEFAULT_FRAMES}); output times of --time "
        f"(default {DEFAULT_TIMES})",
    )
    p.add_argument("--drivers", help="generalised coordinates J1,J2 (default: the file's)")
    p.add_argument(
        "--method",
        default="gauss",
        choices=("gauss", "trapezoid", "fft", "adaptive"),
        help="work integral: gauss (default; exact at jumps), trapezoid or fft on 2^n steps, "
        "adaptive",
    )
    p.add_argument(
        "--n", type=int, default=10, help="2^n steps for trapezoid and fft (default 10)"
    )
    p.add_argument("--harmonics", type=int, help="Fourier terms kept by fft (default all)")
    p.add_argument(
        "--start-speed", type=float, metavar="W0", help="--time: speed at t = 0 (default 0)"
    )
    p.add_argument("--solver", help="--time: auto (default), DOP853, RK45, Radau, BDF, LSODA")
    p.add_argument("--rtol", type=float, help="--time: relative tolerance (default 1e-8)")
    p.add_argument(
        "--max-evaluations",
        type=int,
        metavar="N",
        help="--time: right-hand-side evaluations the run may take (default 5e5)",
    )
    p.add_argument("--csv", metavar="OUT", help="write the table (q, qdot, ..., reactions) here")
    p.add_argument(
        "--max-memory",
        type=int,
        metavar="BYTES",
        help="refuse runs estimated above this (default $MJSTRUCT_MAX_MEMORY_BYTES or 2 GiB)",
    )
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


def run(args: argparse.Namespace) -> int:
    from mjstruct.dynamics.analysis import OUTPUTS, dynamic_analysis
    from mjstruct.dynamics.report import render, write_csv
    from mjstruct.io import read_mechanism

    if args.frames is not None and args.frames < 1:
        raise MechanismError(f"--frames: must be >= 1, got {args.frames}")
    if args.speed is not None and (not math.isfinite(args.speed) or args.speed == 0):
        raise MechanismError("--speed: must be a finite nonzero number")
    for flag in ("start_speed", "rtol", "max_evaluations"):
        if args.time is None and getattr(args, flag) is not None:
            raise MechanismError(f"--{flag.replace('_', '-')}: only with --time")
    if args.time is None and args.solver is not None:
        raise MechanismError("--solver: only with --time")
    if args.time is not None and args.max_memory is not None:
        # a run in time keeps its steps, bounded by --max-evaluations instead
        raise MechanismError("--max-memory: not with --time (see --max-evaluations)")
    if args.qdot0 is not None and not math.isfinite(args.qdot0):
        raise MechanismError("--qdot0: must be a finite number")
    if not 1 <= args.n <= 24:
        raise MechanismError(f"--n: must be in 1..24, got {args.n}")
    if args.harmonics is not None and args.harmonics < 0:
        raise MechanismError(f"--harmonics: must be >= 0, got {args.harmonics}")
    m = read_mechanism(args.file)
    drivers = driver_list(args.drivers, m)
    if args.time is not None:
        return _run_time(args, m, drivers)
    outputs = set(OUTPUTS)
    if args.speed is not None and args.json and not args.csv:
        outputs.discard("coefficients")  # V, W, Q are not in the --speed JSON
    with flag_names(**FLAGS):
        r = dynamic_analysis(
            m,
            outputs=outputs,
            speed=args.speed,
            qdot0=args.qdot0,
            frames=DEFAULT_FRAMES if args.frames is None else args.frames,
            drivers=drivers,
            method=args.method,
            n=args.n,
            harmonics=args.harmonics,
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


def _run_time(args: argparse.Namespace, m: Mechanism, drivers: list[str] | None) -> int:
    from mjstruct.dynamics.time import motion_in_time, time_csv, time_json, time_report
    from mjstruct.output_files import replacing

    with flag_names(**TIME_FLAGS):
        r = motion_in_time(
            m,
            args.time,
            frames=DEFAULT_TIMES if args.frames is None else args.frames,
            qdot0=0.0 if args.start_speed is None else args.start_speed,
            method="auto" if args.solver is None else args.solver,
            rtol=1e-8 if args.rtol is None else args.rtol,
            drivers=drivers,
            **({} if args.max_evaluations is None else {"max_evaluations": args.max_evaluations}),
        )
    if args.csv:
        try:
            # whole or not at all, a link followed, the umask's permissions
            with replacing(args.csv) as tmp, open(tmp, "w") as fh:
                fh.write(time_csv(r))
        except OSError as exc:
            raise MechanismError(f"--csv: cannot write {args.csv} ({exc.strerror})") from None
    if args.json:
        emit_json(time_json(r))
    else:
        emit_text(time_report(r))
    return 0
