"""Pictures of the path-synthesis benchmark for docs/synthesis-design.md.

For each problem of ``benchmarks/bench_synthesis.py`` (seed 0): mjstruct's design
against the targets, whole and near the targets, with the plain differential
evolution's four-bar (the closed form of the benchmark's baseline) traced over one
crank turn beside it (``docs/img/synthesis-bench-designs.png``); and the error
against CPU time of both, run one after the other in this process
(``docs/img/synthesis-bench-history.png``);
the best six-bar designs of the benchmark's atlas case (``--atlas 6 --mj`` on the
18-point curve, seed 0; ``docs/img/synthesis-bench-atlas.png``).

Run from the repository's root: ``python docs/make_synthesis_images.py [designs]
[atlas]`` (both without arguments; a few minutes: it runs the plain differential
evolution once per problem, and the atlas on two workers).
"""

from __future__ import annotations

import io
import math
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_synthesis as bench  # noqa: E402
from mjstruct.design.api import synthesize  # noqa: E402
from mjstruct.plot.design_charts import draw_targets  # noqa: E402

IMG = ROOT / "docs" / "img"
NAMES = ["line6", "curve18", "ellipse10", "timed5"]


def save(fig: Figure, name: str, dpi: int) -> None:
    """``fig`` as docs/img/NAME, 64 colours (a third of the bytes, the same look)."""
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    image = Image.open(buf).convert("RGB").quantize(colors=64, method=Image.Quantize.MEDIANCUT)
    image.save(IMG / name, optimize=True)
    print(f"wrote docs/img/{name}")


def atlas() -> None:
    """The three best designs of different chains of the benchmark's atlas case."""
    r = bench.atlas_case()
    shown: list[str] = []
    fig = plt.figure(figsize=(11.0, 4.2))
    for x in r.ranked:
        if x.result is None or x.candidate.name in shown or len(shown) == 3:
            continue
        shown.append(x.candidate.name)
        ax = fig.add_subplot(1, 3, len(shown))
        draw_targets(x.result.mechanism, ax=ax)
        f = sum(e * e for e in x.result.errors)
        c = x.candidate
        ax.set_title(f"{c.name}\n(frame {c.frame}, driver {c.driver}, point on {c.link}): "
                     f"f = {f:.3g}", fontsize=8)  # fmt: skip
        ax.legend(loc="best", fontsize=6)
    fig.tight_layout()
    save(fig, "synthesis-bench-atlas.png", dpi=80)


def main() -> None:
    what = sys.argv[1:] or ["designs", "atlas"]
    if "designs" in what:
        designs_and_history()
    if "atlas" in what:
        atlas()


def designs_and_history() -> None:
    """Per problem: the design whole and near its targets, both against the plain DE's
    coupler curve; and the best objective so far against CPU time, both runs."""
    import types

    from matplotlib.ticker import LogLocator, NullFormatter

    from mjstruct.design import search

    # the search's record in CPU seconds, like the baseline's and the benchmark's table
    search.time = types.SimpleNamespace(perf_counter=time.process_time)  # type: ignore[attr-defined]
    designs = plt.figure(figsize=(14.0, 7.6))
    history = plt.figure(figsize=(11.0, 7.5))
    for k, name in enumerate(NAMES):
        c0 = time.process_time()
        r = synthesize(bench.task_for(name), seed=0)
        ours_cpu = time.process_time() - c0
        T = len(bench.PROBLEMS[name]["targets"])
        ours_f = sum(e * e for e in r.errors)
        record: list[tuple[float, float, float]] = []
        x, base_cpu = bench.baseline(name, 0, record)
        base_f, ok = bench.baseline_score(name, x)
        if ok:  # scipy's closing polish (L-BFGS-B) after the last generation
            record.append((base_cpu, math.nan, base_f))
        print(f"{name}: mjstruct f = {ours_f:.4g} in {ours_cpu:.1f} s CPU; "
              f"plain DE f = {base_f:.4g}{'' if ok else ' (infeasible)'} "
              f"in {base_cpu:.1f} s CPU", flush=True)  # fmt: skip

        theta = np.linspace(0.0, 2 * math.pi, 721)
        C = bench.closed_form(x, theta)
        mark = "" if ok else ", infeasible"
        targets = np.array(bench.PROBLEMS[name]["targets"])
        for row in (0, 1):
            ax = designs.add_subplot(2, 4, 1 + k + 4 * row)
            draw_targets(r.mechanism, ax=ax)
            ax.plot(C.real, C.imag, "--", color="tab:orange", lw=1.0,
                    label=f"plain DE (f = {base_f:.3g}{mark})")  # fmt: skip
            if row == 0:
                ax.set_title(f"{name}: mjstruct f = {ours_f:.3g}", fontsize=10)
                ax.legend(loc="best", fontsize=6)
            else:  # near the targets
                lo, hi = targets.min(axis=0), targets.max(axis=0)
                pad = 0.3 * float((hi - lo).max())
                ax.set_xlim(lo[0] - pad, hi[0] + pad)
                ax.set_ylim(lo[1] - pad, hi[1] + pad)
                ax.set_aspect("equal", adjustable="box")
                ax.set_title(f"{name}: near the targets", fontsize=9)

        ax = history.add_subplot(2, 2, k + 1)
        hs = [(t, f * f * T) for _, t, f in r.history if math.isfinite(f)]
        if hs:
            ts, fs = zip(*hs, strict=True)
            ax.step(ts, fs, where="post", color="tab:blue", label="mjstruct synthesize")
        bs = [(t, f) for t, _, f in record if math.isfinite(f)]
        if bs:
            ts, fs = zip(*bs, strict=True)
            ax.step(ts, fs, where="post", color="tab:orange", label="plain DE (closed form)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("CPU time (s)")
        ax.set_ylabel("sum of squared target errors")
        never = "" if bs else " (plain DE: never feasible)"
        ax.set_title(name + never, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    designs.tight_layout()
    history.suptitle("best feasible design so far against CPU time (seed 0)", fontsize=11)
    history.tight_layout()
    save(designs, "synthesis-bench-designs.png", dpi=75)
    save(history, "synthesis-bench-history.png", dpi=75)


if __name__ == "__main__":
    main()
