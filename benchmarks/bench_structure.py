"""Structural core timings, measured side by side in one run (medians of repeats).

Prints: whole-process ``mjstruct analyze`` on the four-bar next to the bare interpreter
and a bare ``import networkx``; which heavy libraries the structural path imports; the
in-process full report for the 24-link example and for random 300-link chains with
multiple joints, with [L] (the embedding search) timed separately.

Run: ``python benchmarks/bench_structure.py``
"""

from __future__ import annotations

import random
import subprocess
import sys
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


def process_time(argv: list[str], repeat: int = 7) -> float:
    return median_time(lambda: subprocess.run(argv, check=True, capture_output=True), repeat)[0]


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


def main() -> None:
    py = sys.executable
    four_bar = str(EXAMPLES / "four-bar.json")
    print("== whole process (median of 7 runs, seconds) ==")
    floor = process_time([py, "-c", "pass"])
    nx_import = process_time([py, "-c", "import networkx"])
    analyze = process_time([py, "-m", "mjstruct.cli.main", "analyze", four_bar])
    rows = [
        ("python -c pass", floor),
        ("python -c 'import networkx'", nx_import),
        ("mjstruct analyze four-bar.json", analyze),
    ]
    for label, t in rows:
        print(f"  {label:34s} {t:7.3f}   ratio to bare python {t / floor:5.1f}")
    print(f"  target 0.300 s: analyze/target = {analyze / 0.3:.2f}")

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
