"""``mjstruct dynamics FILE``: inverse dynamics at constant speed, free one-DOF motion
(the equation of motion integrated in q), or motion in time (``--time T``: the reduced
equation of one driver, or Lagrange's equations for several drivers or force elements)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

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
    "q0": "--q0",
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="mechanism file with geometry and dynamics keys (.json or .toml)")
    p.add_argument("--speed", type=float, metavar="W", help="every driver at constant speed W")
    p.add_argument(
        "--qdot0",
        metavar="W0[,W1...]",
        help="free motion under the loads from speed W0 (one driver); with --time: the "
        "initial speeds, one per driver in --drivers order",
    )
    p.add_argument(
        "--time",
        type=float,
        metavar="T",
        help="motion in time from t = 0 to T (any number of drivers)",
    )
    p.add_argument(
        "--q0",
        metavar="Q0[,Q1...]",
        help="--time: initial driver coordinates, one per driver (default the reference)",
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
        "--start-speed",
        metavar="W0[,W1...]",
        help="--time: speeds at t = 0, as --qdot0 with --time (default 0)",
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

    modes = [f for f, v in (("--speed", args.speed), ("--qdot0", args.qdot0)) if v is not None]
    if args.time is None and len(modes) != 1:
        raise MechanismError(
            "--speed: give exactly one of --speed, --qdot0 and --time (--qdot0 may go with --time)"
        )
    if args.time is not None and args.speed is not None:
        raise MechanismError("--speed: not with --time")
    if args.time is not None and args.qdot0 is not None and args.start_speed is not None:
        raise MechanismError(
            "--start-speed: give the initial speeds once (--qdot0 or --start-speed)"
        )
    if args.frames is not None and args.frames < 1:
        raise MechanismError(f"--frames: must be >= 1, got {args.frames}")
    if args.speed is not None and (not math.isfinite(args.speed) or args.speed == 0):
        raise MechanismError("--speed: must be a finite nonzero number")
    for flag in ("start_speed", "rtol", "max_evaluations", "q0"):
        if args.time is None and getattr(args, flag) is not None:
            raise MechanismError(f"--{flag.replace('_', '-')}: only with --time")
    if args.time is None and args.solver is not None:
        raise MechanismError("--solver: only with --time")
    if args.time is not None and args.max_memory is not None:
        # a run in time keeps its steps, bounded by --max-evaluations instead
        raise MechanismError("--max-memory: not with --time (see --max-evaluations)")
    speeds = _numbers(args.qdot0, "--qdot0")
    start = _numbers(args.start_speed, "--start-speed")
    if args.time is None and speeds is not None and len(speeds) != 1:
        raise MechanismError(
            "--qdot0: free motion in q takes one speed; several drivers move in time "
            "(--time T --qdot0 W1,W2)"
        )
    if not 1 <= args.n <= 24:
        raise MechanismError(f"--n: must be in 1..24, got {args.n}")
    if args.harmonics is not None and args.harmonics < 0:
        raise MechanismError(f"--harmonics: must be >= 0, got {args.harmonics}")
    m = read_mechanism(args.file)
    drivers = driver_list(args.drivers, m)
    if args.time is not None:
        given = speeds if speeds is not None else start
        flag = "--qdot0" if speeds is not None else "--start-speed"
        D = len(drivers) if drivers is not None else len(m.drivers or ())
        if D > 1 or "elements" in m.extra:
            return _run_forward(args, m, drivers, given, flag)
        if given is not None and len(given) != 1:
            raise MechanismError(f"{flag}: one speed per driver (1), got {len(given)}")
        return _run_time(args, m, drivers, None if given is None else given[0], flag)
    outputs = set(OUTPUTS)
    if args.speed is not None and args.json and not args.csv:
        outputs.discard("coefficients")  # V, W, Q are not in the --speed JSON
    with flag_names(**FLAGS):
        r = dynamic_analysis(
            m,
            outputs=outputs,
            speed=args.speed,
            qdot0=None if speeds is None else speeds[0],
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


def _numbers(text: str | None, flag: str) -> list[float] | None:
    """A flag's comma-separated numbers (None when not given)."""
    if text is None:
        return None
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise MechanismError(
            f"{flag}: must be a number or a comma-separated list of numbers, got {text!r}"
        ) from None
    if not all(math.isfinite(x) for x in values):
        raise MechanismError(f"{flag}: must be finite numbers")
    return values


def _run_forward(
    args: argparse.Namespace,
    m: Mechanism,
    drivers: list[str] | None,
    speeds: list[float] | None,
    flag: str,
) -> int:
    from mjstruct.dynamics.forward import forward_dynamics
    from mjstruct.dynamics.forward_report import forward_csv, forward_json, forward_report
    from mjstruct.synthesis.parallel import ProgressBar

    q0 = _numbers(args.q0, "--q0")
    bar = ProgressBar.for_cli("motion in time, % of T", json_output=args.json)
    with flag_names(**{**TIME_FLAGS, "qdot0": flag}):
        r = forward_dynamics(
            m, args.time, q0=q0, qdot0=speeds, progress=bar, **_time_options(args, drivers)
        )
    return _emit(args, forward_csv(r) if args.csv else "", forward_json, forward_report, r)


def _time_options(args: argparse.Namespace, drivers: list[str] | None) -> dict[str, Any]:
    """The keyword arguments both solvers in time take from the flags."""
    return {
        "frames": DEFAULT_TIMES if args.frames is None else args.frames,
        "method": "auto" if args.solver is None else args.solver,
        "rtol": 1e-8 if args.rtol is None else args.rtol,
        "drivers": drivers,
        **({} if args.max_evaluations is None else {"max_evaluations": args.max_evaluations}),
    }


def _emit(
    args: argparse.Namespace,
    csv: str,
    as_json: Callable[[Any], dict[str, Any]],
    as_text: Callable[[Any], str],
    r: Any,
) -> int:
    """Write ``csv`` to ``--csv`` (whole or not at all) and print the JSON or the text."""
    from mjstruct.output_files import replacing

    if args.csv:
        try:
            # whole or not at all, a link followed, the umask's permissions
            with replacing(args.csv) as tmp, open(tmp, "w") as fh:
                fh.write(csv)
        except OSError as exc:
            raise MechanismError(f"--csv: cannot write {args.csv} ({exc.strerror})") from None
    if args.json:
        emit_json(as_json(r))
    else:
        emit_text(as_text(r))
    return 0


def _run_time(
    args: argparse.Namespace,
    m: Mechanism,
    drivers: list[str] | None,
    speed: float | None,
    flag: str,
) -> int:
    from mjstruct.dynamics.time import motion_in_time, time_csv, time_json, time_report

    q0 = _numbers(args.q0, "--q0")
    if q0 is not None and len(q0) != 1:
        raise MechanismError(f"--q0: one coordinate per driver (1), got {len(q0)}")
    with flag_names(**{**TIME_FLAGS, "qdot0": flag}):
        r = motion_in_time(
            m,
            args.time,
            q0=None if q0 is None else q0[0],
            qdot0=0.0 if speed is None else speed,
            **_time_options(args, drivers),
        )
    return _emit(args, time_csv(r) if args.csv else "", time_json, time_report, r)
