"""``mjstruct synthesize TASK -o OUT``: the dimensions that make a mechanism do a task."""

from __future__ import annotations

import argparse
import math
import sys
import textwrap
import time
from pathlib import Path
from typing import Any, TextIO

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
        "--budget",
        type=float,
        metavar="SECONDS",
        help="anytime run: stop after SECONDS (wall clock) with the best design found",
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
    if args.budget is not None and not (math.isfinite(args.budget) and args.budget > 0):
        raise MechanismError(f"--budget: must be a positive number of seconds, got {args.budget}")
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
        if args.budget is not None:
            raise MechanismError("--budget: not used with --atlas (its racing sets the effort)")
        return _run_atlas(args, data)
    task = task_from_dict(data, source=str(args.task))
    bar = ProgressBar.for_cli(f"synthesize {task.kind}", args.json)
    flags = {"workers": "--workers", "scheduler": "--scheduler", "seed": "--seed"}
    with flag_names(budget="--budget", **flags):
        result = synthesize(
            task,
            seed=args.seed,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=bar,
            budget=args.budget,
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
        emit_text(render(_text_dict(result), args.output, args.history, args.targets_chart))
    return 0


def _text_dict(result: Any) -> dict[str, Any]:
    """The JSON object with what the text report adds: whether the targets were
    timed (from the written file's ``synthesis`` key) and a four-bar matrix
    synthesis's singular report."""
    d: dict[str, Any] = result.to_dict()
    entry = result.mechanism.extra.get("synthesis")
    if isinstance(entry, dict) and "timed" in entry:
        d["timed"] = entry["timed"]
    if result.task == "fourbar-ms":
        d["report"] = _singular_report(result.mechanism)
    return d


def _singular_report(m: Any) -> str:
    """The built four-bar's singular report, as ``mjstruct singular OUT`` prints it
    (the matrix, class, swing, time ratio, change point, positions and, with the
    task's clearance kept in the file, their zones)."""
    from mjstruct.cli.singular import file_clearance
    from mjstruct.cli.singular import render as render_singular
    from mjstruct.kinematics.tolerances import MAX_CLEARANCE
    from mjstruct.singular.analysis import singular_analysis

    lines = []
    for point in m.points:  # the coupler point: where it is, in the task's terms
        a, b = (complex(*(m.joint(j).at or (0.0, 0.0))) for j in ("A", "B"))
        p = complex(*point.at)
        uv = (p - a) * abs(b - a) / (b - a)
        lines.append(
            f"coupler point {point.id} at ({point.at[0]:.6g}, {point.at[1]:.6g}): "
            f"u = {uv.real:.6g} along A -> B, v = {uv.imag:.6g} to its left, from A "
            "(lengths in the file's unit)"
        )
    analysis = singular_analysis(m, clearance=file_clearance(m, MAX_CLEARANCE))
    return "\n".join([*lines, render_singular(analysis)])


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

    bar: Any = ProgressBar.for_cli(f"synthesize --atlas {args.atlas}", args.json)
    if not bar.enabled:  # no terminal: plain lines on stderr, so a log shows it moving
        bar = ProgressLines(f"synthesize --atlas {args.atlas}", sys.stderr)
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
    lines = atlas_lines(ranking, args.atlas, r.seconds, args.seed)
    lines.append(render(_text_dict(best), args.output, args.history, args.targets_chart))
    emit_text("\n".join(lines))
    return 0


def atlas_lines(ranking: list[dict[str, Any]], links: int, seconds: float, seed: int) -> list[str]:
    """The ``--atlas`` ranking as text: one line per candidate, and the reason a
    candidate is not feasible whole, wrapped at word boundaries under it.

    >>> x = {"objective": None, "feasible": False, "name": "Watt", "frame": "0",
    ...      "driver": "J0", "link": "2", "reason": "its plan needs iteration " * 4}
    >>> print("\\n".join(atlas_lines([x], 6, 1.0, 0)[2:]))
         1             -  Watt (frame 0, driver J0, point on 2)
                        not feasible: its plan needs iteration its plan needs iteration its
                          plan needs iteration its plan needs iteration
    """
    lines = [f"atlas of one-DOF chains with {links} links: {len(ranking)} candidates "
             f"in {seconds:.3g} s (seed {seed}: each candidate's random start comes "
             "from it and the candidate's place in the list)",
             "  rank  objective     topology (frame, driver, point's link)"]  # fmt: skip
    for k, x in enumerate(ranking, 1):
        obj = _num(x["objective"], ".4e") if x["feasible"] else "-"
        where = f"frame {x['frame']}, driver {x['driver']}, point on {x['link']}"
        lines.append(f"  {k:4d}  {obj:>12s}  {x['name']} ({where})")
        if not x["feasible"]:  # the reason whole, on lines of its own
            lines += textwrap.wrap(
                f"not feasible: {x['reason']}",
                width=88,
                initial_indent=" " * 20,
                subsequent_indent=" " * 22,
                break_long_words=False,
                break_on_hyphens=False,
            )
    return lines


class ProgressLines:
    """Progress as plain lines (``label: 12/69 candidates, 34 s``) on a stream that is
    not a terminal: at most one every ``every`` seconds, and the last."""

    def __init__(self, label: str, stream: TextIO, every: float = 10.0) -> None:
        self.label, self.stream, self.every = label, stream, every
        self.t0 = time.perf_counter()
        self.last = -math.inf

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        if done < total and now - self.last < self.every:
            return
        self.last = now
        print(
            f"{self.label}: {done}/{total} candidate searches, {now - self.t0:.0f} s",
            file=self.stream,
            flush=True,
        )


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
    """The text report of a ``synthesize --json`` object (a ``fourbar-ms`` result with
    its singular report under ``report``)."""
    lines = _fourbar_ms_lines(d) if d["task"] == "fourbar-ms" else _fitting_lines(d)
    lines.append(f"wrote {output} (the designed mechanism; its targets under 'synthesis')")
    if chart is not None:
        lines.append(f"wrote {chart} (objective against evaluations and time)")
    if targets_chart is not None:
        lines.append(f"wrote {targets_chart} (the design, its traced path and the targets)")
    return "\n".join(lines)


def _fitting_lines(d: dict[str, Any]) -> list[str]:
    """Path, function and motion: the objective, each target's error and where the
    design meets it (numbered from 1, as on the charts)."""
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
        if timing:
            how = "prescribed" if d.get("timed", True) else "untimed: met in this order"
            lines.append(f"  target  error       q (deg, 0-360; {how})")
        else:
            lines.append("  target  error")
        for i, e in enumerate(d["errors"]):
            q = ""
            if timing and i < len(timing) and timing[i] is not None:
                q = f"  {math.degrees(timing[i]) % 360.0:10.4f}"
            lines.append(f"  {i + 1:6d}  {_num(e, '.3e')}{q}")
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
    if details.get("on_bound"):
        lines.append(
            "  on a bound of its box (a wider region may hold a better design): "
            + ", ".join(details["on_bound"])
        )
    if "angle_offset" in details:
        lines.append(
            f"  angle offset found: {_num(math.degrees(details['angle_offset']), '.6g')} deg "
            "(the targets' angles plus it are the output's)"
        )
    return lines


def _fourbar_ms_lines(d: dict[str, Any]) -> list[str]:
    """The matrix synthesis: the matrix and how it was found, the lengths, the
    requirement's residuals, then the built four-bar's singular report."""
    details = d.get("details", {})
    solve = details.get("solve", {})
    how = solve.get("method", "-")
    if details.get("reference_matrix"):
        how = f"{how}; the reference matrix {details['reference_matrix']}"
    if solve.get("free"):
        how += f"; solved for {', '.join(solve['free'])}"
    if solve.get("defaults"):
        how += f"; {', '.join(solve['defaults'])} by default"
    ms = " ".join(_num(p) for p in details.get("MS", ()))
    lines = [
        f"fourbar-ms synthesis: MS = [{ms}] ({how}), "
        f"{'feasible' if d['feasible'] else 'NOT feasible'}"
    ]
    lengths = details.get("lengths", {})
    if lengths:
        lines.append(
            "  lengths: "
            + ", ".join(f"{k} {_num(v)}" for k, v in lengths.items())
            + " (the file's length unit)"
        )
    for what, e in zip(details.get("errors_of", ()), d["errors"], strict=False):
        unit = " deg" if what == "swing_deg" else ""
        lines.append(f"  requirement {what} met to {_num(e, '.2e')}{unit}")
    report = d.get("report")
    if report:
        lines += ["  " + line for line in str(report).splitlines()]
    return lines
