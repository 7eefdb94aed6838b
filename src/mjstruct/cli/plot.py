"""``mjstruct plot FILE --what CHART -o OUT.svg|png|pdf``: a chart against the driver
coordinate q over one cycle (link angles, ω, ε, point paths, the driver-fixed Jacobian
determinant, a four-bar's transmission angle); the charts are listed in
:data:`mjstruct.plot.charts.CHARTS`."""

from __future__ import annotations

import argparse
import warnings as warnings_module
from typing import TYPE_CHECKING

from mjstruct.cli.draw import (
    add_angle_argument,
    add_model_arguments,
    add_output_arguments,
    finish,
    read_model,
)
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.kinematics.model import KinematicModel


def add_arguments(p: argparse.ArgumentParser) -> None:
    from mjstruct.plot.charts import CHARTS

    add_model_arguments(p)
    p.add_argument("--what", required=True, help=f"chart: {', '.join(CHARTS)}")
    p.add_argument("--frames", type=int, default=360, help="frames over one cycle (default 360)")
    p.add_argument(
        "--ids",
        help="links (angles, omega, eps) or joints/points (paths) to plot, comma-separated",
    )
    add_angle_argument(p)
    add_output_arguments(p, ".svg, .png or .pdf")
    p.add_argument("--dpi", type=int, default=120, help="resolution of a .png (default 120)")
    p.add_argument(
        "--max-memory",
        type=int,
        metavar="BYTES",
        help="memory limit of the estimate (default: MJSTRUCT_MAX_MEMORY_BYTES or 2 GiB)",
    )


def run(args: argparse.Namespace) -> int:
    from mjstruct.plot.charts import chart
    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output

    check_output(args.output, FIGURE_SUFFIXES, name="-o")
    chart(args.what, name="--what")
    if args.frames < 2:
        raise MechanismError(f"--frames: must be >= 2, got {args.frames}")
    if args.dpi < 10:
        raise MechanismError(f"--dpi: must be >= 10, got {args.dpi}")
    model = read_model(args)
    check_frames_memory(model, args.frames, args.max_memory)
    ids = None if args.ids is None else [x.strip() for x in args.ids.split(",") if x.strip()]

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mjstruct.plot.charts import draw_chart
    from mjstruct.plot.files import write_atomically

    try:
        fig = draw_chart(
            model, args.what, args.frames, args.speed, args.stroke, ids, radians=args.radians
        )
    except MechanismError as exc:  # library parameter names -> flags
        text = str(exc)
        for param, flag in (
            ("ids:", "--ids:"),
            ("what:", "--what:"),
            ("drivers:", "--drivers:"),
            ("speed:", "--speed:"),
            ("qdot0:", "--speed:"),
            ("frames:", "--frames:"),
        ):
            if text.startswith(param):
                text = flag + text[len(param) :]
        raise MechanismError(text) from None
    try:
        with warnings_module.catch_warnings():
            # advice for interactive use (the legend's best place is slow to find among
            # many points), not a problem of the chart written
            warnings_module.filterwarnings("ignore", "Creating legend with loc", UserWarning)
            fig.tight_layout()
            write_atomically(args.output, lambda tmp: fig.savefig(tmp, dpi=args.dpi), name="-o")
    finally:
        plt.close(fig)
    warnings = []
    if not fig.axes or not any(ax.get_lines() for ax in fig.axes):
        warnings.append("nothing to plot")
    what = f"chart {args.what} of {model.mechanism.name or 'mechanism'}, {args.frames} frames"
    return finish(args, "plot", {"what": args.what, "frames": args.frames}, warnings, what)


def check_frames_memory(
    model: KinematicModel, frames: int, max_memory: int | None, frame_bytes: int = 0
) -> int:
    """Refuse a frame count whose estimated memory exceeds the limit; the estimate.

    The motion is estimated as a kinematic sweep without checks
    (:func:`mjstruct.kinematics.memory.sweep_bytes`), plus ``frame_bytes`` per frame
    for what the command keeps of each frame (an animation's images).
    """
    from mjstruct.cli.output import flag_names
    from mjstruct.kinematics.memory import MEMORY_ENV, memory_limit, sweep_bytes

    with flag_names(max_memory="--max-memory"):
        limit = memory_limit(max_memory)
    per_frame = sweep_bytes(model, 1, checks=False) + frame_bytes
    need = per_frame * frames
    if need > limit:
        raise MechanismError(
            f"--frames: {frames} frames need about {need:.2g} bytes, over the limit of "
            f"{limit:.3g} bytes (--max-memory, or {MEMORY_ENV}); at most "
            f"{limit // per_frame} frames fit"
        )
    return need
