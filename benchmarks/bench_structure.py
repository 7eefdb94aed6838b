"""Structural core timings, measured side by side in one run (medians of repeats).

Prints: the CPU time of whole processes in a regular install (``pip install .`` into a
fresh venv this script makes; ``--venv DIR`` reuses one): ``mjstruct analyze --json``
on the four-bar and on the 24-link example, ``mjstruct kinematics`` of the four-bar at
3600 frames, next to the bare interpreter and bare ``import numpy`` / ``import
networkx``, run alternately (goals: the four-bar within 3x of ``python -c pass``, the
24-link example within 4x); which heavy libraries the structural path imports; the
in-process full report for the 24-link example and for random 300-link chains with
multiple joints, with [L] (the embedding search) timed separately.

Run: ``python benchmarks/bench_structure.py [REPEAT] [--venv DIR] [--startup-only]``
(start-up runs, default 41)
"""

from __future__ import annotations

import argparse
import os
import random
import statistics
import subprocess
import sys
import tempfile
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


def regular_install(where: Path) -> Path:
    """A fresh venv at ``where`` with mjstruct installed as the README tells users
    (``pip install .``, not editable: an editable install adds its finder to every
    interpreter's start, ``python -c pass`` included); its ``bin`` folder."""
    subprocess.run([sys.executable, "-m", "venv", str(where)], check=True)
    bin_ = where / "bin"
    subprocess.run(
        [str(bin_ / "python"), "-m", "pip", "install", "-q", "--disable-pip-version-check",
         str(ROOT)],
        check=True, capture_output=True,
    )  # fmt: skip
    return bin_


def cpu_of(argv: list[str], env: dict[str, str]) -> float:
    """CPU seconds (user + system) of one run of ``argv`` (the child and its threads)."""
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    if status:
        raise SystemExit(f"{' '.join(argv)} failed: {proc.stderr.read().decode()}")  # type: ignore[union-attr]
    proc.stderr.close()  # type: ignore[union-attr]
    return usage.ru_utime + usage.ru_stime


def start_up(repeat: int, venv: Path | None = None) -> None:
    """The commands a user runs against ``python -c pass``, in a regular install in a
    fresh venv made here (or ``venv``, already made so), run alternately (so that the
    machine's load hits all alike), medians of the CPU time of each process.

    Bytecode is written at install time (pip compiles what it installs), as in any
    installed copy.  One BLAS thread (``OPENBLAS_NUM_THREADS=1``): numpy's thread pool
    would otherwise add its start to whichever command imports numpy.
    """
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        bin_ = venv / "bin" if venv else regular_install(Path(tmp) / "venv")
        made = f"made in {time.perf_counter() - t0:.0f} s" if not venv else f"given: {venv}"
        py, cli = str(bin_ / "python"), str(bin_ / "mjstruct")
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
        env["OPENBLAS_NUM_THREADS"] = "1"
        four_bar = str(EXAMPLES / "four-bar.json")
        ex24 = str(EXAMPLES / "seed002-ex5-24-link.json")
        cmds = {
            "python -c pass": [py, "-c", "pass"],
            "python -c 'import numpy'": [py, "-c", "import numpy"],
            "python -c 'import networkx'": [py, "-c", "import networkx"],
            "mjstruct analyze four-bar --json": [cli, "analyze", four_bar, "--json"],
            "mjstruct analyze 24-link --json": [cli, "analyze", ex24, "--json"],
            "mjstruct kinematics four-bar --frames 3600 --json": [
                cli, "kinematics", four_bar, "--frames", "3600", "--json"
            ],
        }  # fmt: skip
        for argv in cmds.values():
            cpu_of(argv, env)  # warm the file cache
        times: dict[str, list[float]] = {k: [] for k in cmds}
        for _ in range(repeat):
            for label, argv in cmds.items():
                times[label].append(cpu_of(argv, env))
    med = {k: statistics.median(v) for k, v in times.items()}
    floor = med["python -c pass"]
    print(
        f"== whole process in a regular install (venv {made}), run alternately "
        f"(median of {repeat}, CPU seconds) =="
    )
    for label, t in med.items():
        print(f"  {label:50s} {t:7.4f}   ratio to bare python {t / floor:5.2f}")
    print("  goals: analyze --json within 3x of python -c pass, the 24-link example within 4x")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("repeat", nargs="?", type=int, default=41, help="start-up runs")
    ap.add_argument("--venv", type=Path, help="a venv with a regular install (else made)")
    ap.add_argument("--startup-only", action="store_true")
    args = ap.parse_args()
    py = sys.executable
    four_bar = str(EXAMPLES / "four-bar.json")
    start_up(args.repeat, args.venv)
    if args.startup_only:
        return

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
