"""Pictures of the path-synthesis benchmark for docs/synthesis-design.md.

For each problem of ``benchmarks/bench_synthesis.py`` (seed 0): mjstruct's design
against the targets, with the plain differential evolution's four-bar (the closed
form of the benchmark's baseline) traced over one crank turn beside it
(``docs/img/synthesis-bench-designs.png``); and the error against run time of both,
run one after the other in this process (``docs/img/synthesis-bench-history.png``).

Run from the repository's root: ``python docs/make_synthesis_images.py`` (a few
minutes: it runs the plain differential evolution once per problem).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_synthesis as bench  # noqa: E402
from mjstruct.design.api import synthesize  # noqa: E402
from mjstruct.plot.design_charts import draw_targets  # noqa: E402

IMG = ROOT / "docs" / "img"
NAMES = ["line6", "curve18", "ellipse10", "timed5"]


def main() -> None:
    designs = plt.figure(figsize=(11.0, 9.0))
    history = plt.figure(figsize=(11.0, 7.5))
    for k, name in enumerate(NAMES, 1):
        t0 = time.perf_counter()
        r = synthesize(bench.task_for(name), seed=0)
        ours_wall = time.perf_counter() - t0
        T = len(bench.PROBLEMS[name]["targets"])
        ours_f = sum(e * e for e in r.errors)
        record: list[tuple[float, float, float]] = []
        x, _cpu = bench.baseline(name, 0, record)
        base_f, ok = bench.baseline_score(name, x)
        print(f"{name}: mjstruct f = {ours_f:.4g} in {ours_wall:.1f} s wall; "
              f"plain DE f = {base_f:.4g}{'' if ok else ' (infeasible)'} "
              f"in {record[-1][1] if record else math.nan:.1f} s wall", flush=True)  # fmt: skip

        ax = designs.add_subplot(2, 2, k)
        draw_targets(r.mechanism, ax=ax)
        theta = np.linspace(0.0, 2 * math.pi, 721)
        C = bench.closed_form(x, theta)
        mark = "" if ok else ", infeasible"
        ax.plot(C.real, C.imag, "--", color="tab:orange", lw=1.0,
                label=f"plain DE's coupler curve (f = {base_f:.3g}{mark})")  # fmt: skip
        ax.set_title(f"{name}: mjstruct f = {ours_f:.3g}", fontsize=10)
        ax.legend(loc="best", fontsize=7)

        ax = history.add_subplot(2, 2, k)
        hs = [(t, f * f * T) for _, t, f in r.history if math.isfinite(f)]
        if hs:
            ts, fs = zip(*hs, strict=True)
            ax.step(ts, fs, where="post", color="tab:blue", label="mjstruct synthesize")
        bs = [(t, f) for _, t, f in record if math.isfinite(f)]
        if bs:
            ts, fs = zip(*bs, strict=True)
            ax.step(ts, fs, where="post", color="tab:orange", label="plain DE (closed form)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time (s)")
        ax.set_ylabel("sum of squared target errors")
        ax.set_title(name, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    designs.tight_layout()
    history.suptitle("best feasible design so far against run time (seed 0)", fontsize=11)
    history.tight_layout()
    designs.savefig(IMG / "synthesis-bench-designs.png", dpi=90)
    history.savefig(IMG / "synthesis-bench-history.png", dpi=90)
    print("wrote docs/img/synthesis-bench-designs.png, docs/img/synthesis-bench-history.png")


if __name__ == "__main__":
    main()
