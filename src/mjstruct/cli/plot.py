"""``mjstruct plot FILE --what CHART -o OUT.svg|png|pdf``: a chart against the driver
coordinate q over one cycle (link angles, ω, ε, point paths, the driver-fixed Jacobian
determinant, a four-bar's transmission angle); the charts are listed in
:data:`mjstruct.plot.charts.CHARTS`."""

from __future__ import annotations

import argparse

from mjstruct.cli.draw import add_model_arguments, add_output_arguments, finish, read_model
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    from mjstruct.plot.charts import CHARTS

    add_model_arguments(p)
    p.add_argument("--what", required=True, help=f"chart: {', '.join(CHARTS)}")
    p.add_argument("--frames", type=int, default=360, help="frames over one cycle (default 360)")
    p.add_argument(
        "--ids",
        help="links (angles, omega, eps) or joints/points (paths) to plot, comma-separated",
    )
    add_output_arguments(p, ".svg, .png or .pdf")
    p.add_argument("--dpi", type=int, default=120, help="resolution of a .png (default 120)")


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
    ids = None if args.ids is None else [x.strip() for x in args.ids.split(",") if x.strip()]

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mjstruct.plot.charts import draw_chart
    from mjstruct.plot.files import write_atomically

    try:
        fig = draw_chart(model, args.what, args.frames, args.speed, args.stroke, ids)
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
        fig.tight_layout()
        write_atomically(args.output, lambda tmp: fig.savefig(tmp, dpi=args.dpi), name="-o")
    finally:
        plt.close(fig)
    warnings = []
    if not fig.axes or not any(ax.get_lines() for ax in fig.axes):
        warnings.append("nothing to plot")
    return finish(args, "plot", {"what": args.what, "frames": args.frames}, warnings)
