"""Every performance goal, each measured by its own benchmark, run RUNS times in turn.

Each benchmark script races mjstruct against its peer or limit in one process and
prints the ratio; this script runs them one after another (``--runs`` rounds), reads
the ratio from what they print, and ends with one table: the goal, its limit, the
ratio of every round and whether the goal held in all of them.  The machine's load is
printed with every round (the machine is shared: ratios measured side by side are the
figures that compare, single times are not).

Run: ``python benchmarks/goals.py [--runs 3] [--only kinematics,dynamics,...]``.
The atlas goals need ``geng`` (Debian package ``nauty``) for their peer; without it
that row says so.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Goal:
    label: str
    limit: float
    pattern: str  # the ratio is its first group, in the output of the goal's script
    nth: int = 0  # which match, when a script prints several such lines
    per: float = 1.0  # the matched number divided by this is the ratio (a limit printed raw)


#: script (with arguments) -> the goals it measures
GOALS: dict[str, tuple[list[str], list[Goal]]] = {
    "kinematics": (
        ["bench_kinematics.py", "--repeat", "21"],
        [
            Goal("four-bar, fresh + every table / numpy closed form", 1.6,
                 r"^\s+fresh mechanism from file, every table read\s+[\d.]+ ms\s+([\d.]+)x"),
            Goal("Watt-II, fresh + every table / numpy closed form", 1.6,
                 r"Watt: fresh mechanism from file, every table read\s+[\d.]+ ms\s+([\d.]+)x"),
            Goal("four-bar, fresh + every table / pylinkage + numba", 1.0,
                 r"fresh call, every table read / pylinkage: ([\d.]+)"),
            Goal("Watt-II, fresh + every table / pylinkage + numba", 1.0,
                 r"fresh call, every table read / pylinkage: ([\d.]+)", nth=1),
        ],
    ),
    "scale": (
        ["bench_kinematics_scale.py", "--sizes", "1000,4000", "--cpu", "--rounds", "3"],
        [
            Goal("t(4000 links) / t(1000 links), planning incl.", 4.8,
                 r"t\(4000\)/t\(1000\), default checks, planning included: ([\d.]+)"),
            Goal("peak RSS at 4000 links / 4 GiB", 1.0, r"peak RSS at 4000 links: ([\d.]+) MB",
                 per=4096.0),
        ],
    ),
    "closure": (
        ["bench_closure.py", "--cpu", "--only-default"],
        [
            Goal("class-IV, fresh + every table / batched Newton", 2.0,
                 r"fresh default call / hand-written Newton: ([\d.]+)x"),
        ],
    ),
    "startup": (
        ["bench_structure.py", "21", "--startup-only"],
        [
            Goal("analyze four-bar --json / python -c pass", 3.0,
                 r"mjstruct analyze four-bar --json\s+[\d.]+\s+ratio to bare python\s+([\d.]+)"),
            Goal("analyze 24-link --json / python -c pass", 4.0,
                 r"mjstruct analyze 24-link --json\s+[\d.]+\s+ratio to bare python\s+([\d.]+)"),
        ],
    ),
    "dynamics": (
        ["bench_dynamics.py"],
        [
            Goal("Zhivago free motion, cold, 36 frames / 20 ms", 1.0,
                 r"zhivago-dynamics, 36 frames: free motion, cold .*?goal 20 ms: ratio ([\d.]+)"),
            Goal("Zhivago free motion, cold, 3600 frames / 0.2 s", 1.0,
                 r"zhivago-dynamics, 3600 frames: free motion, cold .*?200 ms: ratio ([\d.]+)"),
        ],
    ),
    "atlas": (
        ["bench_atlas.py", "--goals", "--repeat", "3"],
        [
            Goal("MJ atlas F=1 n=12 command: wall / 60 s", 1.0,
                 r"MJ atlas F=1 n=12, 2 workers: wall s\s+[\d.]+\s+[\d.]+\s+([\d.]+)"),
            Goal("MJ atlas F=1 n=12 command: ΣRSS / 300 MB", 1.0,
                 r"peak memory, Σ RSS of the tree MB\s+[\d.]+\s+[\d.]+\s+([\d.]+)"),
            Goal("SJ atlas F=1 n=14 command / geng + filter", 1.2,
                 r"SJ atlas F=1 n=14, 2 workers / geng\+filter\s+([\d.]+)"),
        ],
    ),
    "singular": (
        ["bench_singular.py"],
        [
            Goal("MS4 singular analysis / 3600-frame dense sweep", 10.0,
                 r"MS4 four-bar\s+singular_analysis .*?ratio\s+([\d.]+)"),
        ],
    ),
    # the dimensional synthesis's own benchmark (its problems, seeds and peer are
    # described there): mjstruct's CPU time on the timed five-point task against its
    # differential-evolution peer's; not in the default set (minutes per round)
    "synthesis": (
        ["bench_synthesis.py", "--problems", "timed5", "--seeds", "3"],
        [
            Goal("synthesis timed5: time / DE's time", 0.1,
                 r"^timed5\s+[\d.e+-]+\s+[\d.]+\s+[\d.e+inf-]+\s+[\d.]+\s+([\d.]+)"),
        ],
    ),
}  # fmt: skip


#: benchmarks run only when named in ``--only``
OPT_IN = ("synthesis",)


def load() -> str:
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


def run(script: list[str]) -> str:
    """The script's output (it fails loudly: a benchmark that breaks is not a pass)."""
    done = subprocess.run(
        [sys.executable, str(HERE / script[0]), *script[1:]],
        cwd=HERE,
        capture_output=True,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),
    )
    if done.returncode != 0:
        raise SystemExit(f"{script[0]} failed:\n{done.stdout}\n{done.stderr}")
    return done.stdout


def ratio(goal: Goal, text: str) -> float | None:
    found = [float(m.group(1)) / goal.per for m in re.finditer(goal.pattern, text, re.MULTILINE)]
    return found[goal.nth] if len(found) > goal.nth else None


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument(
        "--only",
        default=",".join(k for k in GOALS if k not in OPT_IN),
        help="benchmarks to run: " + ", ".join(GOALS) + f" ({', '.join(OPT_IN)} only if named)",
    )
    ap.add_argument("--verbose", action="store_true", help="print each benchmark's output")
    ap.add_argument(
        "--write-doc",
        metavar="MD",
        help="replace the section 'The latest run' of this page (docs/performance.md) "
        "with the table",
    )
    ap.add_argument("--log", metavar="FILE", help="append every benchmark's output to FILE")
    args = ap.parse_args()
    chosen = [k for k in args.only.split(",") if k]
    unknown = set(chosen) - set(GOALS)
    if unknown:
        ap.error(f"unknown benchmark(s): {', '.join(sorted(unknown))}")
    found: dict[str, list[float | None]] = {}
    loads: list[float] = []
    start = time.strftime("%Y-%m-%d %H:%M", time.gmtime())
    for r in range(args.runs):
        print(f"round {r + 1} of {args.runs}, load {load()}", flush=True)
        loads.append(float(load().split()[0]))
        for key in chosen:
            script, goals = GOALS[key]
            t0 = time.perf_counter()
            text = run(script)
            if args.verbose:
                print(text)
            if args.log:
                with open(args.log, "a") as fh:
                    fh.write(f"== round {r + 1}: {' '.join(script)} ==\n{text}\n")
            shown = []
            for goal in goals:
                value = ratio(goal, text)
                found.setdefault(goal.label, []).append(value)
                shown.append("-" if value is None else f"{value:.2f}")
            took = time.perf_counter() - t0
            loads.append(float(load().split()[0]))
            print(f"  {key:<11} {', '.join(shown):<28} ({took:.0f} s, load {load()})", flush=True)
    end = time.strftime("%H:%M", time.gmtime())
    rows = []
    print(f"\n{'goal (ratio)':<50} {'limit':>5}  {'rounds':<24} verdict")
    for key in chosen:
        for goal in GOALS[key][1]:
            values = found[goal.label]
            if all(v is None for v in values):
                verdict = "NOT MEASURED (peer absent or output changed)"
            elif any(v is None for v in values):
                verdict = "INCOMPLETE"
            else:
                held = sum(v <= goal.limit for v in values if v is not None)
                verdict = "PASS" if held == len(values) else f"FAIL ({held} of {len(values)})"
            rounds = " ".join("-" if v is None else f"{v:.2f}" for v in values)
            print(f"{goal.label:<50} {goal.limit:5.2f}  {rounds:<24} {verdict}")
            rows.append((goal, values, verdict))
    if args.write_doc:
        write_doc(Path(args.write_doc), rows, args.runs, f"{start}–{end} UTC", loads)


def write_doc(
    page: Path,
    rows: list[tuple[Goal, list[float | None], str]],
    runs: int,
    when: str,
    loads: list[float],
) -> None:
    """Replace the section "The latest run" of ``page`` with this run's table."""
    head = "| goal (ratio) | limit | " + " | ".join(f"round {k + 1}" for k in range(runs))
    lines = [
        f"{when}, `python benchmarks/goals.py --runs {runs}`, load average (1 min) "
        f"{min(loads):.1f}–{max(loads):.1f} on two cores:",
        "",
        head + " | verdict |",
        "|---|---|" + "---|" * runs + "---|",
    ]
    for goal, values, verdict in rows:
        cells = " | ".join("-" if v is None else f"{v:.2f}" for v in values)
        word = {"PASS": "holds"}.get(verdict, verdict.lower().replace("fail", "fails"))
        lines.append(f"| {goal.label} | {goal.limit:g} | {cells} | {word} |")
    text = page.read_text(encoding="utf-8")
    top = "## The latest run\n"
    a = text.index(top) + len(top)
    b = text.index("\n## ", a)
    page.write_text(text[:a] + "\n" + "\n".join(lines) + "\n" + text[b:], encoding="utf-8")


if __name__ == "__main__":
    main()
