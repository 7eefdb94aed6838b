"""Structural core timings, measured side by side in one run (medians of repeats).

Prints: whole-process ``mjstruct analyze --json`` on the four-bar next to the bare
interpreter and a bare ``import networkx``, run alternately (goal: within 3x of
``python -c pass``); which heavy libraries the structural path imports; the
in-process full report for the 24-link example and for random 300-link chains with
multiple joints, with [L] (the embedding search) timed separately.

Run: ``python benchmarks/bench_structure.py [REPEAT]`` (start-up runs, default 41)
"""

from __future__ import annotations

import os
import random
import shutil
import statistics
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.report import structural_report
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.structure.loops import loop_assortment
from timing import median_time

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "catalogs" / "examples"


def random_chain(n_links: int, seed: int, mj_share: float = 0.15) -> Mechanism:
    """A connected chain: a spanning tree of joints plus loop-closing joints, some MJs."""
    rng = random.Random(seed)
    joints: list[list[int]] = []
    for link in range(1, n_links):
        joints.append([rng.randrange(link), link])
    for _ in range(n_links // 2):
        a, b = rng.sample(range(n_links), 2)
        joints.append([a, b])
    for js in joints:
        if rng.random() < mj_share:
            extra = rng.randrange(n_links)
            if extra not in js:
                js.append(extra)
    return Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)], frame=0)


def grid_chain(rows: int, cols: int, seed: int) -> Mechanism:
    """A planar chain: links on a grid, joints along grid edges, some merged into MJs."""
    rng = random.Random(seed)
    joints: list[list[int]] = []

    def node(r: int, c: int) -> int:
        return r * cols + c

    for r in range(rows):
        for c in range(cols):
            right = node(r, c + 1) if c + 1 < cols else None
            up = node(r + 1, c) if r + 1 < rows else None
            # merging the right and up joints of a link keeps the drawing planar
            if right is not None and up is not None and rng.random() < 0.2:
                joints.append([node(r, c), right, up])
                continue
            if right is not None:
                joints.append([node(r, c), right])
            if up is not None:
                joints.append([node(r, c), up])
    return Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)], frame=0)


def start_up(repeat: int) -> None:
    """``mjstruct analyze --json`` on the four-bar against ``python -c pass``, run
    alternately (so that the machine's load hits both alike), medians of wall time.

    The installed ``mjstruct`` script is run as a user runs it.  Bytecode is written
    first (an environment with PYTHONDONTWRITEBYTECODE would otherwise compile every
    module on every start, which no installed copy does).
    """
    py = sys.executable
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    subprocess.run(
        [py, "-m", "compileall", "-q", str(ROOT / "src" / "mjstruct")],
        env=env, check=True, capture_output=True,
    )  # fmt: skip
    script = shutil.which("mjstruct", path=str(Path(py).parent)) or shutil.which("mjstruct")
    analyze = [script] if script else [py, "-m", "mjstruct.cli.main"]
    four_bar = str(EXAMPLES / "four-bar.json")
    cmds = {
        "python -c pass": [py, "-c", "pass"],
        "python -c 'import networkx'": [py, "-c", "import networkx"],
        "mjstruct analyze four-bar --json": [*analyze, "analyze", four_bar, "--json"],
    }
    times: dict[str, list[float]] = {k: [] for k in cmds}
    for _ in range(repeat):
        for label, argv in cmds.items():
            t0 = time.perf_counter()
            subprocess.run(argv, env=env, check=True, capture_output=True)
            times[label].append(time.perf_counter() - t0)
    med = {k: statistics.median(v) for k, v in times.items()}
    floor = med["python -c pass"]
    print(f"== whole process, run alternately (median of {repeat}, seconds) ==")
    for label, t in med.items():
        print(f"  {label:34s} {t:7.3f}   ratio to bare python {t / floor:5.2f}")
    print("  goal: analyze --json within 3x of python -c pass")


def main() -> None:
    py = sys.executable
    four_bar = str(EXAMPLES / "four-bar.json")
    start_up(int(sys.argv[1]) if len(sys.argv) > 1 else 41)

    probe = (
        "import sys; from mjstruct.cli.main import main; import io, contextlib\n"
        f"with contextlib.redirect_stdout(io.StringIO()): main(['analyze', {four_bar!r}])\n"
        "print(','.join(m for m in ('sympy','matplotlib','scipy','networkx') if m in sys.modules))"
    )
    heavy = subprocess.run([py, "-c", probe], capture_output=True, text=True, check=True)
    print(f"  heavy modules imported by analyze: {heavy.stdout.strip() or 'none'}")

    print("\n== in-process full report (median, milliseconds) ==")
    ex24 = read_mechanism(EXAMPLES / "seed002-ex5-24-link.json")
    radial = read_mechanism(EXAMPLES / "radial-engine-5.json")
    cases: list[tuple[str, Mechanism]] = [
        ("24-link example ([MJ structure 2020], ex. 5)", ex24),
        ("radial engine, 5 cylinders", radial),
        ("random 300-link chain with MJs", random_chain(300, seed=1)),
        ("planar 300-link grid chain with MJs", grid_chain(15, 20, seed=2)),
    ]
    print(f"  {'case':38s} {'no [L]':>8s} {'[L] only':>9s} {'full':>8s} {'canon.':>8s}  rule")
    for label, m in cases:

        def report(with_loops: bool, m: Mechanism = m) -> None:
            # a fresh Mechanism each call: no cached adjacency carried over
            structural_report(Mechanism(links=m.links, joints=m.joints), with_loops=with_loops)

        t_core = median_time(partial(report, False), repeat=5, number=3)[0]
        t_full = median_time(partial(report, True), repeat=5, number=1)[0]
        t_loops = median_time(partial(loop_assortment, m), repeat=5, number=1)[0]
        t_canon = median_time(partial(canonical_code, m), repeat=5, number=5)[0]
        la = loop_assortment(m)
        rule = la.rule if la else "not planar"
        print(
            f"  {label:38s} {t_core * 1e3:8.2f} {t_loops * 1e3:9.2f} {t_full * 1e3:8.2f}"
            f" {t_canon * 1e3:8.3f}  {rule}"
        )
    print("  targets: 24-link full report < 5 ms; 300-link report < 200 ms ([L] reported apart)")


if __name__ == "__main__":
    main()
