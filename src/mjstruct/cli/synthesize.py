"""``mjstruct synthesize TASK -o OUT``: the dimensions that make a mechanism do a task."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from mjstruct.cli.output import dumps, emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError

#: what ``-o`` may be: a mechanism file
OUTPUT_SUFFIXES = (".json", ".toml")


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("task", help="task file (.json or .toml; docs/synthesis-design.md)")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="mechanism file to write")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--workers", type=int, default=1, help="processes for the restarts (default 1)")
    p.add_argument(
        "--scheduler", default=None, help="Dask scheduler address (optional dask extra)"
    )
    p.add_argument(
        "--history",
        metavar="CHART",
        help="also chart the objective against evaluations and time (.svg, .png, .pdf)",
    )
    p.add_argument(
        "--targets-chart",
        metavar="CHART",
        help="also draw the design with its traced path and the targets (.svg, .png, .pdf)",
    )
    p.add_argument(
        "--atlas",
        type=int,
        metavar="N",
        help="try every one-DOF chain of N links (inversions, drivers, point links) and rank them",
    )
    p.add_argument(
        "--mj", action="store_true", help="with --atlas: chains with multiple joints too"
    )
    p.add_argument(
        "--max-memory",
        type=int,
        metavar="BYTES",
        help="refuse searches estimated above this (default $MJSTRUCT_MAX_MEMORY_BYTES or 2 GiB)",
    )
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


def run(args: argparse.Namespace) -> int:
    from mjstruct.design.api import synthesize
    from mjstruct.design.task import read_task_data, task_from_dict
    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output
    from mjstruct.synthesis.parallel import ProgressBar

    if args.workers < 1:
        raise MechanismError(f"--workers: need at least 1, got {args.workers}")
    if args.seed < 0:
        raise MechanismError(f"--seed: must be >= 0, got {args.seed}")
    check_output(args.output, OUTPUT_SUFFIXES, name="-o")
    if args.history is not None:
        check_output(args.history, FIGURE_SUFFIXES, name="--history")
    if args.targets_chart is not None:
        check_output(args.targets_chart, FIGURE_SUFFIXES, name="--targets-chart")
    if args.mj and args.atlas is None:
        raise MechanismError("--mj: needs --atlas")
    if args.max_memory is not None and args.max_memory <= 0:
        raise MechanismError(
            f"--max-memory: must be a positive number of bytes, got {args.max_memory}"
        )
    data = read_task_data(args.task)  # once: the task may come from standard input
    _check_task_outputs(args, data)
    if args.atlas is not None:
        return _run_atlas(args, data)
    task = task_from_dict(data, source=str(args.task))
    bar = ProgressBar.for_cli(f"synthesize {task.kind}", args.json)
    with flag_names(workers="--workers", scheduler="--scheduler", seed="--seed"):
        result = synthesize(
            task,
            seed=args.seed,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=bar,
            max_memory=args.max_memory,
        )
    _write_outputs(args, result)
    if args.json:
        out = result.to_dict()
        out["output"] = args.output
        if args.history is not None:
            out["history_chart"] = args.history
        if args.targets_chart is not None:
            out["targets_chart"] = args.targets_chart
        emit_json(out)
    else:
        emit_text(render(result.to_dict(), args.output, args.history, args.targets_chart))
    return 0


def _check_task_outputs(args: argparse.Namespace, data: dict[str, Any]) -> None:
    """Before any work: no output onto the task's mechanism file (nor onto the task,
    nor two outputs onto one file: :func:`~mjstruct.cli.output.check_outputs`), and no
    chart the task cannot have."""
    from mjstruct.cli.output import check_outputs

    mechanism = data.get("mechanism")
    if isinstance(mechanism, str):
        check_outputs(args, {mechanism: f"the task's mechanism file ({mechanism})"})
    if args.targets_chart is not None and data.get("task") == "fourbar-ms":
        raise MechanismError(
            "--targets-chart: a fourbar-ms task has no targets to draw (draw the "
            "written four-bar with mjstruct draw)"
        )


def _run_atlas(args: argparse.Namespace, data: dict[str, Any]) -> int:
    """``--atlas N``: every candidate topology on the task, ranked; the best written."""
    from mjstruct.design.atlas import synthesize_atlas
    from mjstruct.synthesis.parallel import ProgressBar

    bar = ProgressBar.for_cli(f"synthesize --atlas {args.atlas}", args.json)
    with flag_names(links="--atlas", workers="--workers", scheduler="--scheduler"):
        r = synthesize_atlas(
            data,
            links=args.atlas,
            mj=args.mj,
            seed=args.seed,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=bar,
            max_memory=args.max_memory,
        )
    best = r.best
    if best is None:
        from mjstruct.errors import NumericalError

        why = r.ranked[0].reason if r.ranked else "no candidate"
        raise NumericalError(f"no feasible design: no candidate topology gave one ({why})")
    _write_outputs(args, best)
    ranking = [x.to_dict() for x in r.ranked]
    if args.json:
        out = best.to_dict()
        out["output"] = args.output
        out["atlas"] = ranking
        out["atlas_seconds"] = r.seconds
        emit_json(out)
        return 0
    lines = [f"atlas of one-DOF chains with {args.atlas} links: {len(ranking)} candidates "
             f"in {r.seconds:.3g} s (seed {args.seed})",
             "  rank  objective     topology (frame, driver, point's link)"]  # fmt: skip
    for k, x in enumerate(ranking, 1):
        obj = _num(x["objective"], ".4e") if x["feasible"] else "-"
        where = f"frame {x['frame']}, driver {x['driver']}, point on {x['link']}"
        note = "" if x["feasible"] else f"  ({x['reason'][:60]})"
        lines.append(f"  {k:4d}  {obj:>12s}  {x['name']} ({where}){note}")
    lines.append(render(best.to_dict(), args.output, args.history, args.targets_chart))
    emit_text("\n".join(lines))
    return 0


def _write_outputs(args: argparse.Namespace, result: Any) -> None:
    """The design (``-o``) and the charts asked for, all or nothing: every chart is
    drawn first, then each file is written under a temporary name, and only when all
    are written are they moved into place."""
    from contextlib import ExitStack

    from mjstruct.io import mechanism_to_dict, mechanism_to_toml
    from mjstruct.output_files import replacing

    if Path(args.output).suffix.lower() == ".toml":
        text = mechanism_to_toml(result.mechanism)
    else:
        text = dumps(mechanism_to_dict(result.mechanism)) + "\n"
    figures: list[tuple[str, str, Any]] = []
    if args.history is not None or args.targets_chart is not None:
        import matplotlib

        matplotlib.use("Agg")
    try:
        if args.history is not None:
            from mjstruct.plot.design_charts import draw_history

            figures.append((args.history, "--history", draw_history(result)))
        if args.targets_chart is not None:
            from mjstruct.plot.design_charts import draw_targets

            with flag_names(mechanism="--targets-chart"):
                fig = draw_targets(result.mechanism)
            figures.append((args.targets_chart, "--targets-chart", fig))
        flag = "-o"
        try:
            with ExitStack() as files:
                tmp = files.enter_context(replacing(args.output, "-o"))
                Path(tmp).write_text(text, encoding="utf-8")
                for path, flag, fig in figures:
                    tmp = files.enter_context(replacing(path, flag))
                    try:
                        fig.savefig(tmp)
                    except ValueError as exc:  # matplotlib refusing the figure
                        raise MechanismError(f"{flag}: cannot draw the chart ({exc})") from None
        except OSError as exc:
            reason = exc.strerror or type(exc).__name__
            raise MechanismError(f"{flag}: cannot write ({reason})") from None
    finally:
        if figures:
            import matplotlib.pyplot as plt

            for _, _, fig in figures:
                plt.close(fig)


def _num(x: Any, fmt: str = ".6g") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def render(
    d: dict[str, Any], output: str, chart: str | None = None, targets_chart: str | None = None
) -> str:
    """The text report of a ``synthesize --json`` object."""
    lines = [
        f"{d['task']} synthesis: objective {_num(d['objective'])} "
        f"(root mean square error over {len(d['errors'])} target(s)), "
        f"{'feasible' if d['feasible'] else 'NOT feasible'}",
        f"  {d['evaluations']} candidate evaluations in {_num(d['seconds'], '.3g')} s "
        f"(seed {d['seed']})",
    ]
    details = d.get("details", {})
    timing = details.get("timing")
    if d["errors"]:
        lines.append("  target  error" + ("         q" if timing else ""))
        for i, e in enumerate(d["errors"]):
            q = f"  {_num(timing[i], '10.6f')}" if timing and i < len(timing) else ""
            lines.append(f"  {i:6d}  {_num(e, '.3e')}{q}")
    if d["margins"]:
        lines.append("  constraint margins (>= 0: met)")
        for k, v in d["margins"].items():
            lines.append(f"    {k}: {_num(v, '.4g')}")
    for key, label in (
        ("motion", "four-bar motion"),
        ("min_transmission_deg", "smallest dyad angle (deg)"),
    ):
        if key in details:
            value = details[key]
            shown = _num(value, ".4g") if isinstance(value, float) else str(value)
            lines.append(f"  {label}: {shown}")
    lines += _singular_lines(details.get("singular"))
    lines.append(f"wrote {output} (the designed mechanism; its targets under 'synthesis')")
    if chart is not None:
        lines.append(f"wrote {chart} (objective against evaluations and time)")
    if targets_chart is not None:
        lines.append(f"wrote {targets_chart} (the design, its traced path and the targets)")
    return "\n".join(lines)


def _singular_lines(singular: dict[str, Any] | None) -> list[str]:
    """The built mechanism's singular positions and fold arcs with their classes of
    [Four-bar clearances] (a ``fourbar-ms`` result; none for the other tasks)."""
    if not singular:
        return []
    out = ["  singular positions (input angle in deg, class of [Four-bar clearances]):"]
    for p in singular["singular"]:
        c = p.get("classification") or {}
        out.append(f"    {p['kind']:<15} {_turn_deg(p['q']):9.4f}  {c.get('notation', '-')}")
    for a in singular["fold_arcs"]:
        c = a.get("classification") or {}
        start = _turn_deg(a["q_from"])
        span = f"{start:.4f} to {start + math.degrees(a['q_to'] - a['q_from']):.4f}"
        what = "locked input" if a["kind"] == "input_limit" else "dwell"
        out.append(f"    fold arc ({what}) {span}  {c.get('notation', '-')}")
    return out


def _turn_deg(q: float) -> float:
    """An angle (rad) in degrees within one turn, to 1e-4 (2 pi is 0)."""
    return round(math.degrees(q), 4) % 360.0
