"""Atlas enumeration and canonical-code timings against the project's time targets.

The targets and the expected counts (the published simple-joint counts, see
docs/synthesis.md) are those of the timing table in docs/synthesis.md; the 24-link chain
is example 5 of [MJ structure 2020] (docs/references.md).

With ``--geng`` it races the simple-joint atlas (2 workers) against nauty's ``geng``
(Debian package ``nauty``, command ``nauty-geng``; pynauty ships no geng) generating
every connected graph with n vertices, 3(n-1)/2 - F/2 edges and minimum degree 2,
streamed into a vectorised admissibility filter on 2 processes (every link subset S
of the sizes that can be a smallest rigid one, ``3(|S|-1) - 2 e(S) >= 1``: one
float32 matrix product per subset size and batch of graphs, sizes smallest first),
counts compared (``--verify``: the chains too); geng's generation alone is timed too.
It says so and skips the race when geng is not installed.

With ``--mj12`` it runs the command a user runs, ``mjstruct atlas --dof 1 --links 12
--mj --workers 2``, and samples the memory of its process tree.  ``--goals`` runs both
goals through the command (MJ atlas at 12 links: <= 60 s wall, <= 300 MB peak Σ RSS of
the tree; ``mjstruct atlas --dof 1 --links 14 --workers 2`` within 1.2x geng + filter),
the commands and the peer alternated in every round, medians of the rounds, and prints
each ratio with PASS/FAIL and the exponent of the atlas's time against its number of
chains.

Run: ``python benchmarks/bench_atlas.py [--repeat R] [--pyslvs PYTHON] [--geng]
[--mj12] [--goals]``.  Without those it prints the median wall time of each case, the
count found, and the ratio to the target; with ``--pyslvs`` also times pyslvs's
structural synthesis (run in that interpreter, e.g. a separate venv) on the same
simple-joint cases, side by side in the same run.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
from functools import partial
from pathlib import Path

from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.synthesis.admissibility import is_admissible
from mjstruct.synthesis.atlas import atlas
from timing import median_time

ROOT = Path(__file__).resolve().parents[1]

# (label, F, n, mj, workers, target seconds or None, expected count or None)
CASES = [
    ("F=1 n=10 SJ", 1, 10, False, 1, 5.0, 230),
    ("F=1 n=12 SJ, 2 workers", 1, 12, False, 2, 60.0, 6856),
    ("F=1 n=12 SJ, 1 worker", 1, 12, False, 1, None, 6856),
    ("F=1 n=10 with MJs", 1, 10, True, 1, 60.0, None),
    ("F=2 n=9 SJ", 2, 9, False, 1, None, 35),
    ("F=2 n=9 with MJs", 2, 9, True, 1, None, None),
]

PYSLVS_SCRIPT = r"""
import json, sys, time
from pyslvs.graph import (link_synthesis, contracted_link_synthesis, contracted_graph,
    conventional_graph)
nl, nj, repeat = map(int, sys.argv[1:4])
times = []
for _ in range(repeat):
    t = time.perf_counter()
    out = []
    for la in link_synthesis(nl, nj):
        cgs = contracted_graph(la)
        for cla in contracted_link_synthesis(la):
            out.extend(conventional_graph(cgs, cla, 1))  # 1: the non-degenerate chains
    times.append(time.perf_counter() - t)
times.sort()
edges = [list(map(list, g.edges)) for g in out]
print(json.dumps({"median": times[len(times) // 2], "edges": edges}))
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--pyslvs", default=None, help="python interpreter that has pyslvs")
    ap.add_argument("--pyslvs-max-links", type=int, default=12)
    ap.add_argument("--geng", action="store_true", help="race geng + a numpy filter")
    ap.add_argument("--sizes", default="10,12,14", help="links for --geng (F = 1)")
    ap.add_argument("--verify", action="store_true", help="--geng: compare the chains too")
    ap.add_argument("--mj12", action="store_true", help="MJ atlas F=1 n=12: time and memory")
    ap.add_argument("--goals", action="store_true", help="both atlas goals, PASS/FAIL")
    args = ap.parse_args()
    if args.goals:
        goals(args.repeat)
        return
    if args.geng:
        race_geng(args.repeat, tuple(int(x) for x in args.sizes.split(",")), args.verify)
    if args.mj12:
        wall, memory = run_mj12(args.repeat)
        print(
            f"median {wall:.1f} s (goal {GOAL_MJ12_S:.0f} s: ratio {wall / GOAL_MJ12_S:.2f}), "
            f"peak Σ RSS {memory:.0f} MB (goal {GOAL_MJ12_MB:.0f} MB: "
            f"ratio {memory / GOAL_MJ12_MB:.2f})"
        )
    if args.geng or args.mj12:
        return
    print(f"{'case':<26} {'median s':>9} {'count':>7} {'target s':>9} {'target/median':>14}")
    for label, F, n, mj, workers, target, expected in CASES:
        t, a = median_time(partial(atlas, F, n, mj=mj, workers=workers), args.repeat)
        count = a.count
        ok = "" if expected is None or count == expected else f"  WRONG (expected {expected})"
        ratio = f"{target / t:14.1f}" if target else f"{'-':>14}"
        tgt = f"{target:9.1f}" if target else f"{'-':>9}"
        print(f"{label:<26} {t:9.3f} {count:7d} {tgt} {ratio}{ok}")
    m = read_mechanism(ROOT / "catalogs" / "examples" / "seed002-ex5-24-link.json")
    reps = 200
    t, _ = median_time(lambda: [canonical_code(m) for _ in range(reps)], 5)
    per = t / reps * 1e3
    print(f"{'canonical code, 24 links':<26} {per:8.3f}m {'':>7} {2.0:8.1f}m {2.0 / per:14.1f}")
    if args.pyslvs:
        print("\npyslvs structural synthesis, same simple-joint cases (side by side):")
        print(
            f"{'case':<26} {'mjstruct s':>11} {'pyslvs s':>9} {'ratio':>7} "
            f"{'ours/theirs':>13} {'rigid':>5} {'missing':>7}"
        )
        for label, F, n, _mj, _w, _t, _expected in CASES:
            if _mj or _w != 1 or n > args.pyslvs_max_links:
                continue
            nj = (3 * (n - 1) - F) // 2
            ours, a = median_time(partial(atlas, F, n), args.repeat)
            proc = subprocess.run(
                [args.pyslvs, "-c", PYSLVS_SCRIPT, str(n), str(nj), str(args.repeat)],
                capture_output=True,
                text=True,
                timeout=3600,
            )
            if proc.returncode:
                print(f"{label:<26} pyslvs failed: {proc.stderr.strip().splitlines()[-1:]}")
                continue
            r = json.loads(proc.stdout)
            ours_codes = {c.canonical for c in a.chains}
            theirs = [
                Mechanism.build([(f"J{k}", e) for k, e in enumerate(es)]) for es in r["edges"]
            ]
            codes = {canonical_code(m) for m in theirs}
            rigid = sum(not is_admissible(m) for m in theirs)
            missing = len(ours_codes - codes)
            print(
                f"{label:<26} {ours:11.3f} {r['median']:9.3f} {r['median'] / ours:7.1f} "
                f"{len(ours_codes):>6}/{len(theirs):<6} {rigid:>5} {missing:>7}"
            )


GENG = "nauty-geng"
GENG_BLOCK = 8192  # graphs per block handed to a filter worker
GOAL_GENG = 1.2  # the atlas (2 workers) within this factor of geng + filter
GOAL_MJ12_S = 60.0  # F = 1, 12 links with MJs, 2 workers
GOAL_MJ12_MB = 300.0


def _rigid_tests(n: int, F: int) -> list[tuple[object, float]]:
    """Per subset size to test, smallest first: (inside, need), ``inside`` the float32
    matrix (vertex pair, subset) of the pairs inside each subset of that size.

    A subset S of links is rigid when 2 e(S) >= 3 |S| - 3 (e(S): joints inside S).
    Only the sizes that can hold a smallest rigid subset are tested:

    - in geng's output (simple, triangle-free, minimum degree 2) |S| <= 4 never is
      rigid, and for F = 1 (2e = 3n - 4) neither is |S| >= n - 2 (two removed links
      take >= 3 joints with them);
    - an even |S| is never the smallest: 2 e(S) >= 3|S| - 2 there (3|S| - 3 is odd), so
      some link of S has at most 2 joints inside S, and S without it is rigid too.
    """
    from itertools import combinations

    import numpy as np

    top = n - 3 if F == 1 else n - 1
    pairs = [(i, j) for j in range(n) for i in range(j)]  # graph6's bit order
    out = []
    for size in range(5, top + 1, 2):
        subsets = [sum(1 << v for v in c) for c in combinations(range(n), size)]
        member = (np.array(subsets)[:, None] >> np.arange(n)) & 1
        inside = np.array([member[:, i] & member[:, j] for i, j in pairs], dtype=np.float32)
        out.append((inside, (3 * size - 3) / 2))
    return out


_TESTS: dict[tuple[int, int], list[tuple[object, float]]] = {}


def _filter_block(job: tuple[int, int, bytes, bool]) -> tuple[int, int, list[bytes]]:
    """(graphs, admissible ones, their graph6 lines if asked) of a block of geng's
    output: the subset sizes smallest first, each on the graphs no smaller size
    rejected (one float32 matrix product per size and 1024 graphs)."""
    import numpy as np

    n, F, block, keep = job
    if (n, F) not in _TESTS:
        _TESTS[n, F] = _rigid_tests(n, F)
    raw = np.frombuffer(block, dtype=np.uint8)
    width = block.index(b"\n") + 1
    raw = raw.reshape(-1, width)
    six = raw[:, 1:-1] - 63  # graph6: n, then the upper triangle, 6 bits a byte
    bits = np.unpackbits(six[:, :, None], axis=2)[:, :, 2:].reshape(len(raw), -1)
    X = bits[:, : n * (n - 1) // 2].astype(np.float32)
    alive = np.arange(len(raw))
    for inside, need in _TESTS[n, F]:
        rigid = np.zeros(len(alive), dtype=bool)
        for lo in range(0, len(alive), 1024):
            joints_inside = X[alive[lo : lo + 1024]] @ inside  # e(S), graphs x subsets
            rigid[lo : lo + 1024] = (joints_inside >= need - 0.25).any(axis=1)  # type: ignore[operator]
        alive = alive[~rigid]
    lines = [bytes(raw[k, :-1]) for k in alive] if keep else []
    return len(raw), len(alive), lines


def _one_blas_thread() -> None:
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def geng_admissible(F: int, n: int, workers: int = 2, keep: bool = False):  # type: ignore[no-untyped-def]
    """The independent enumerator: geng generates the simple-joint candidates (connected,
    biconnected -C: F = 1 chains are never fractionated; triangle-free -t: a triangle
    is a rigid sub-chain; minimum degree 2; 3(n-1)/2 - F/2 joints), a pool of
    ``workers`` processes filters geng's stream block by block (:func:`_filter_block`).
    Returns (graphs, admissible, their graph6 lines if ``keep``)."""
    import multiprocessing

    e = (3 * (n - 1) - F) // 2
    flags = "-Ctq" if F == 1 else "-ctq"
    proc = subprocess.Popen(
        [GENG, flags, "-d2", str(n), f"{e}:{e}"], stdout=subprocess.PIPE, bufsize=1 << 20
    )
    assert proc.stdout is not None
    width = (n * (n - 1) // 2 + 5) // 6 + 2  # graph6 line for n <= 62, newline included

    def blocks():  # type: ignore[no-untyped-def]
        while chunk := proc.stdout.read(width * GENG_BLOCK):
            yield (n, F, chunk, keep)

    graphs = admissible = 0
    lines: list[bytes] = []
    # one BLAS thread per filter process: two processes on two cores
    with multiprocessing.Pool(workers, initializer=_one_blas_thread) as pool:
        for g, a, kept in pool.imap(_filter_block, blocks()):
            graphs, admissible = graphs + g, admissible + a
            lines.extend(kept)
    proc.wait()
    return graphs, admissible, lines


def _graph6_joints(line: bytes, n: int) -> list[list[int]]:
    bits = "".join(f"{c - 63:06b}" for c in line[1:])
    pairs = [(i, j) for j in range(n) for i in range(j)]
    return [[i, j] for (i, j), b in zip(pairs, bits, strict=False) if b == "1"]


def race_geng(
    repeat: int, sizes: tuple[int, ...], verify: bool, clock: str = "wall"
) -> float | None:
    """Race the atlas against geng + filter at each size; the ratio at the largest
    size (None when geng is absent)."""
    import shutil
    import time

    from mjstruct.synthesis.canonical_chains import chain_code
    from timing import race

    if shutil.which(GENG) is None:
        print(f"{GENG}: not installed (apt-get install nauty): the geng race is skipped")
        return None
    print(f"simple-joint atlas, F = 1, wall time, medians of {repeat} rotations (load {_load()}):")
    print("  mjstruct: atlas(1, n, workers=2)")
    print("  peer: geng -Ct -d2 streaming into a vectorised rigid-subset filter on 2 processes")
    print(
        f"{'n':>3} {'mjstruct s':>11} {'geng+filter s':>14} {'geng alone s':>13} {'ratio':>6} "
        f"{'goal':>5} {'chains':>8} {'peer':>8} {'geng graphs':>12}"
    )
    ratio = None
    for n in sizes:
        got: dict[str, object] = {}

        def ours(n: int = n, got: dict[str, object] = got) -> None:
            got["ours"] = atlas(1, n, workers=2, limit=None)

        def peer(n: int = n, got: dict[str, object] = got) -> None:
            got["peer"] = geng_admissible(1, n, workers=2)

        def generation(n: int = n) -> None:
            e = (3 * (n - 1) - 1) // 2
            subprocess.run([GENG, "-Ctuq", "-d2", str(n), f"{e}:{e}"], check=True)

        t_ours, t_peer, t_geng = race([ours, peer, generation], repeat)
        a = got["ours"]
        graphs, count, _ = got["peer"]  # type: ignore[misc]
        ratio = t_ours / t_peer
        goal = f"{GOAL_GENG:5.1f}" if n == max(sizes) else f"{'-':>5}"
        flag = "" if a.count == count else "  COUNTS DIFFER"  # type: ignore[attr-defined]
        print(
            f"{n:3d} {t_ours:11.2f} {t_peer:14.2f} {t_geng:13.2f} {ratio:6.2f} {goal} "
            f"{a.count:8d} {count:8d} {graphs:12d}{flag}"  # type: ignore[attr-defined]
        )
        if flag:
            ratio = float("inf")
        if verify:
            t0 = time.perf_counter()
            _, _, lines = geng_admissible(1, n, workers=2, keep=True)
            theirs = {chain_code(n, _graph6_joints(g6, n))[0] for g6 in lines}
            ours_codes = {c.canonical for c in a.chains}  # type: ignore[attr-defined]
            same = "the same chains" if theirs == ours_codes else "DIFFERENT chains"
            print(
                f"    verified: geng's {len(theirs)} admissible graphs, canonical codes by "
                f"chain_code: {same} ({time.perf_counter() - t0:.0f} s)"
            )
            if theirs != ours_codes:
                ratio = float("inf")
    return ratio


def _load() -> str:
    import os

    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


def _tree_memory(pid: int) -> tuple[float, float]:
    """(Σ PSS, Σ RSS) in MB of a process and its descendants (Linux /proc)."""
    pss = rss = 0.0
    todo = [pid]
    while todo:
        p = todo.pop()
        try:
            with open(f"/proc/{p}/smaps_rollup") as fh:
                for line in fh:
                    if line.startswith("Pss:"):
                        pss += int(line.split()[1]) / 1024
                    elif line.startswith("Rss:"):
                        rss += int(line.split()[1]) / 1024
            with open(f"/proc/{p}/task/{p}/children") as fh:
                todo.extend(int(x) for x in fh.read().split())
        except (FileNotFoundError, ProcessLookupError, ValueError):
            continue
    return pss, rss


def mjstruct_command() -> list[str]:
    """The ``mjstruct`` command of this interpreter's environment, as a user runs it."""
    import shutil
    import sys

    script = shutil.which("mjstruct", path=str(Path(sys.executable).parent))
    return [script] if script else [sys.executable, "-m", "mjstruct"]


def run_cli(argv: list[str]) -> dict[str, float]:
    """Run one command (the count read from its summary line) and sample the memory of its process
    tree every 20 ms: wall seconds, CPU seconds of the tree (getrusage of the waited
    children), peak Σ PSS (each shared page counted once, split between the processes
    sharing it) and peak Σ RSS (shared pages counted in every process: what the goal
    counts) in MB, and the number of chains the command printed."""
    import time

    t0 = time.perf_counter()
    # the summary is short: read after the end, without filling the pipe
    child = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    peak_pss = peak_rss = 0.0
    while child.poll() is None:
        pss, rss = _tree_memory(child.pid)
        peak_pss, peak_rss = max(peak_pss, pss), max(peak_rss, rss)
        time.sleep(0.02)
    wall = time.perf_counter() - t0
    if child.returncode:
        raise SystemExit(f"{' '.join(argv)} failed: {child.stderr.read().decode()}")  # type: ignore[union-attr]
    first = child.stdout.readline().decode()  # type: ignore[union-attr]
    child.stdout.read()  # type: ignore[union-attr]
    count = re.search(r": (\d+) chains", first)
    return {
        "wall": wall,
        "pss": peak_pss,
        "rss": peak_rss,
        "count": int(count[1]) if count else -1,
    }


def _median(xs: list[float]) -> float:
    import statistics

    return statistics.median(xs)


def run_mj12(repeat: int) -> tuple[float, float]:
    """``mjstruct atlas --dof 1 --links 12 --mj --workers 2`` (the command a user runs,
    its output thrown away), ``repeat`` runs: medians of (wall s, peak Σ RSS MB)."""
    cmd = [*mjstruct_command(), "atlas", "--dof", "1", "--links", "12", "--mj", "--workers", "2"]
    print(f"{' '.join(cmd[-8:])}, {repeat} runs (load {_load()}):")
    print(f"{'run':>4} {'wall s':>7} {'peak ΣPSS MB':>13} {'peak ΣRSS MB':>13}")
    walls, peaks = [], []
    for k in range(repeat):
        r = run_cli(cmd)
        walls.append(r["wall"])
        peaks.append(r["rss"])
        print(f"{k + 1:4d} {r['wall']:7.1f} {r['pss']:13.0f} {r['rss']:13.0f}")
    return _median(walls), _median(peaks)


def goals(repeat: int) -> None:
    """Both atlas goals, measured in one run, each with its ratio and verdict.

    Every round runs, in turn: the MJ atlas command at 12 links, the simple-joint atlas
    command at 14 links, and geng + filter at 14 links (each in its own process tree;
    the memory of the commands sampled); each figure is the median over the rounds.
    The simple-joint command at 12 links runs in each round too: the exponent of the
    atlas's time against its number of chains (12 to 14 links) is printed."""
    import platform
    import shutil
    import time

    print(f"atlas goals, {platform.node()}, {os.cpu_count()} cores, load {_load()}\n")
    cli = mjstruct_command()
    mj12 = [*cli, "atlas", "--dof", "1", "--links", "12", "--mj", "--workers", "2"]
    sj = {n: [*cli, "atlas", "--dof", "1", "--links", str(n), "--workers", "2"] for n in (12, 14)}
    have_geng = shutil.which(GENG) is not None
    got: dict[str, list[float]] = {}

    def keep(key: str, value: float) -> None:
        got.setdefault(key, []).append(value)

    print(
        f"{'round':>5} {'MJ12 wall s':>12} {'MJ12 ΣRSS MB':>13} {'MJ12 ΣPSS MB':>13} "
        f"{'SJ12 wall s':>12} {'SJ14 wall s':>12} {'SJ14 ΣRSS MB':>13} {'geng14 s':>9} "
        f"{'load':>14}"
    )
    counts: dict[int, int] = {}  # geng + filter's
    chains: dict[int, int] = {}  # the command's
    for k in range(repeat):
        r = run_cli(mj12)
        keep("mj_wall", r["wall"])
        keep("mj_rss", r["rss"])
        keep("mj_pss", r["pss"])
        for n, argv in sj.items():
            r = run_cli(argv)
            keep(f"sj{n}", r["wall"])
            keep(f"sj{n}_rss", r["rss"])
            chains[n] = int(r["count"])
        if have_geng:
            t0 = time.perf_counter()
            _, counts[14], _ = geng_admissible(1, 14, workers=2)
            keep("geng", time.perf_counter() - t0)
        geng_s = f"{got['geng'][-1]:9.1f}" if have_geng else f"{'-':>9}"
        print(
            f"{k + 1:5d} {got['mj_wall'][-1]:12.1f} {got['mj_rss'][-1]:13.0f} "
            f"{got['mj_pss'][-1]:13.0f} {got['sj12'][-1]:12.2f} {got['sj14'][-1]:12.2f} "
            f"{got['sj14_rss'][-1]:13.0f} {geng_s} {_load():>14}"
        )
    med = {key: _median(v) for key, v in got.items()}
    exponent = math.log(med["sj14"] / med["sj12"]) / math.log(chains[14] / chains[12])
    print(
        f"\nsimple-joint atlas command: {chains[12]} chains at 12 links, {chains[14]} at 14; "
        f"time against chains: exponent {exponent:.2f} (medians)"
    )
    if have_geng and counts[14] != chains[14]:
        print(f"COUNTS DIFFER: geng + filter {counts[14]}, mjstruct {chains[14]}")
    rows = [
        ("MJ atlas F=1 n=12, 2 workers: wall s", med["mj_wall"], GOAL_MJ12_S),
        ("  same: peak memory, Σ RSS of the tree MB", med["mj_rss"], GOAL_MJ12_MB),
    ]
    print(f"\n{'goal (medians)':<48} {'measured':>9} {'limit':>7} {'ratio':>6}  verdict")
    for label, value, limit in rows:
        verdict = "PASS" if value <= limit else "FAIL"
        print(f"{label:<48} {value:9.1f} {limit:7.1f} {value / limit:6.2f}  {verdict}")
    label = "SJ atlas F=1 n=14, 2 workers / geng+filter"
    if not have_geng:
        print(f"{label:<48} {'-':>9} {GOAL_GENG:7.2f} {'-':>6}  SKIPPED (no {GENG})")
    else:
        ratio = med["sj14"] / med["geng"]
        if counts[14] != chains[14]:
            ratio = float("inf")
        verdict = "PASS" if ratio <= GOAL_GENG else "FAIL"
        print(f"{label:<48} {ratio:9.2f} {GOAL_GENG:7.2f} {ratio / GOAL_GENG:6.2f}  {verdict}")
    print(f"(load at the end {_load()})")


if __name__ == "__main__":
    main()
