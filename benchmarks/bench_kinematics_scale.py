"""Kinematics at scale: time and peak memory from 4 to 4000 links, measured per size.

The family: k four-bars sharing one crank (the crank's pin ``A`` is one multiple joint
of the crank and all k couplers; n = 2 + 2k links).  Each size's mechanism is written
to a file once; every timed call reads it afresh (``read_mechanism``) and runs the
user's call on it, so planning is inside every figure, as in a user's first call.
For each size, in a fresh process (so that its peak resident memory is its own):
planning alone (file read and ``KinematicModel.build``), the default
``kinematic_analysis`` (checks on) and the one with ``checks=False`` at 3600 frames,
and the default call at a quarter of the frames (the exponent against frames).
``--rounds`` runs every size once per round, sizes in turn (the machine's load hits
them alike); each figure is the median over the rounds of the per-process medians.
Prints medians, time per link, the log-log exponents against links between
consecutive sizes (of the default call and of planning: near 1 when linear) and
against frames (3600 against 900 frames at that size), the peak RSS, and the goals:
t(4000)/t(1000) <= 4.8 for the default call including planning, 4000 links run by
default (not refused by the memory guard) within 4 GiB of peak memory.  With
``--full-checks`` the checked column runs the full Jacobian check
(``checks="full"``: rank and determinant from sparse entries), against the same goals.

Run: ``python benchmarks/bench_kinematics_scale.py [--frames N] [--sizes 4,18,...]
[--rounds N] [--full-checks] [--cpu] [--plot docs/img/kin-scaling.png]``; ``--plot`` draws time
and peak memory against the number of links on log-log axes.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import time

SIZES = (4, 10, 18, 34, 66, 130, 258, 514, 1000, 2000, 4000)


def _one(
    n: int, frames: int, repeat: int, level: bool | str = True, cpu: bool = False
) -> dict[str, float]:
    """Measure one size (run in a child process)."""
    import tempfile
    from pathlib import Path

    from mjstruct.io import mechanism_to_dict, read_mechanism
    from mjstruct.kinematics.memory import sweep_bytes
    from mjstruct.kinematics.model import KinematicModel
    from mjstruct.kinematics.solver import kinematic_analysis
    from mjstruct.testing import shared_crank

    tmp = tempfile.TemporaryDirectory()
    path = Path(tmp.name) / f"shared-crank-{n}.json"
    path.write_text(json.dumps(mechanism_to_dict(shared_crank((n - 2) // 2))))

    def timed(fn) -> float:  # type: ignore[no-untyped-def]
        ts = []
        clock = time.process_time if cpu else time.perf_counter
        for _ in range(repeat):
            t0 = clock()
            fn()
            ts.append(clock() - t0)
        return sorted(ts)[len(ts) // 2]

    def call(frames: int, checks: bool | str) -> object:
        # the user's call on a mechanism read afresh: planning inside
        r = kinematic_analysis(read_mechanism(path), frames=frames, checks=checks)
        if checks:
            r.checks  # noqa: B018  (computed when read)
        return r

    m = read_mechanism(path)
    out = {"links": float(len(m.links))}
    out["plan"] = timed(lambda: KinematicModel.build(read_mechanism(path)))
    out["no_checks"] = timed(lambda: call(frames, False))
    out["checks"] = timed(lambda: call(frames, level))
    out["quarter"] = timed(lambda: call(frames // 4, level))
    r = call(frames, level)
    out["valid"] = float(r.valid.mean())  # type: ignore[attr-defined]
    out["factor_error"] = float(r.checks["jacobian"]["det_from_plan_error"] or -1)  # type: ignore[attr-defined]
    out["rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    # the guard's estimate of the default call, against the measured peak
    out["estimate_mb"] = sweep_bytes(KinematicModel.build(m), frames, checks=level) / 2**20
    tmp.cleanup()
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--frames", type=int, default=3600)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=3, help="run all sizes this many times, in turn")
    ap.add_argument("--sizes", default=",".join(str(s) for s in SIZES))
    ap.add_argument("--plot", help="write a log-log plot of time and peak memory (PNG)")
    ap.add_argument(
        "--full-checks",
        action="store_true",
        help="the checks column with the full Jacobian check (checks='full')",
    )
    ap.add_argument(
        "--cpu", action="store_true", help="CPU time of each size's process, not wall time"
    )
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    level: bool | str = "full" if args.full_checks else True
    label = "full checks" if args.full_checks else "default checks"
    if args.child:
        print(json.dumps(_one(args.child, args.frames, args.repeat, level, args.cpu)))
        return
    print(
        f"k four-bars sharing one crank, {args.frames} frames, median of {args.repeat} "
        f"in each of {args.rounds} round(s) (each size in its own process, sizes in turn); "
        f"'checks' = {label}; {'CPU' if args.cpu else 'wall'} time"
    )
    print(
        f"{'links':>6} {'plan ms':>9} {'no checks ms':>13} {'checks ms':>10} "
        f"{'checks us/link':>15} {'slope':>6} {'peak MB':>8} {'est. MB':>8} {'valid':>6} "
        f"{'det err':>8} {'plan us/link':>13} {'plan slope':>11} {'frames exp.':>11}"
    )
    prev = None
    rows = []
    sizes = [int(s) for s in args.sizes.split(",")]
    # every round runs each size once (its own process), sizes in turn: the machine's
    # load hits all sizes alike; per size, the median over the rounds of each figure
    runs: dict[int, list[dict[str, float]]] = {n: [] for n in sizes}
    for _ in range(args.rounds):
        for n in sizes:
            cmd = [sys.executable, __file__, "--child", str(n), "--frames", str(args.frames)]
            cmd += ["--repeat", str(args.repeat)] + (["--full-checks"] if args.full_checks else [])
            cmd += ["--cpu"] if args.cpu else []
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode:
                sys.exit(f"size {n} failed:\n{done.stderr}")
            runs[n].append(json.loads(done.stdout))
    for n in sizes:
        got = {k: sorted(r[k] for r in runs[n])[len(runs[n]) // 2] for k in runs[n][0]}
        slope, plan_slope = (
            (
                math.log(got[key] / prev[key]) / math.log(got["links"] / prev["links"])
                for key in ("checks", "plan")
            )
            if prev
            else (float("nan"), float("nan"))
        )
        print(
            f"{int(got['links']):6d} {got['plan'] * 1e3:9.1f} {got['no_checks'] * 1e3:13.1f} "
            f"{got['checks'] * 1e3:10.1f} {got['checks'] / got['links'] * 1e6:15.0f} "
            f"{slope:6.2f} {got['rss_mb']:8.0f} {got['estimate_mb']:8.0f} {got['valid']:6.2f} "
            f"{got['factor_error']:8.1e} {got['plan'] / got['links'] * 1e6:13.1f} "
            f"{plan_slope:11.2f} {math.log(got['checks'] / got['quarter']) / math.log(4):11.2f}"
        )
        prev = got
        rows.append(got)
    by = {int(r["links"]): r for r in rows}
    if 1000 in by and 4000 in by:
        for key, name in (("checks", label), ("no_checks", "checks off")):
            ratio = by[4000][key] / by[1000][key]
            print(
                f"t(4000)/t(1000), {name}, planning included: {ratio:.2f} (goal <= 4.8; "
                f"linear 4.0; exponent {math.log(ratio) / math.log(4):.2f})"
            )
            each = " ".join(
                f"{r4[key] / r1[key]:.2f}" for r1, r4 in zip(runs[1000], runs[4000], strict=True)
            )
            print(f"  the same ratio in each round: {each}")
        print(f"peak RSS at 4000 links: {by[4000]['rss_mb']:.0f} MB (goal <= 4096)")
    if args.plot:
        plot(rows, args.frames, args.plot)


def plot(rows: list[dict[str, float]], frames: int, path: str) -> None:
    """Time (plan, analysis with and without checks) and peak memory against size."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = [r["links"] for r in rows]
    fig, (ax, am) = plt.subplots(1, 2, figsize=(9, 3.6))
    for key, label in (
        ("checks", "default (checks)"),
        ("no_checks", "checks off"),
        ("plan", "plan"),
    ):
        ax.loglog(n, [r[key] for r in rows], "o-", label=label)
    ax.loglog(n, [rows[0]["checks"] * x / n[0] for x in n], "k:", lw=0.8, label="linear")
    ax.set_xlabel("links")
    ax.set_ylabel("seconds")
    ax.set_title(f"time, {frames} frames")
    ax.legend(fontsize=8)
    am.loglog(n, [r["rss_mb"] for r in rows], "o-", color="C3", label="peak RSS")
    am.loglog(n, [r["estimate_mb"] for r in rows], "s--", color="C4", label="guard's estimate")
    am.legend(fontsize=8)
    am.set_xlabel("links")
    am.set_ylabel("MB")
    am.set_title("peak memory (default call)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
