"""Atlas enumeration and canonical-code timings against the project's time targets.

The targets and the expected counts (the published simple-joint counts, see
docs/synthesis.md) are those of the timing table in docs/synthesis.md; the 24-link chain
is example 5 of [MJ structure 2020] (docs/references.md).

With ``--geng`` it races the simple-joint atlas (2 workers) against nauty's ``geng``
(Debian package ``nauty``, command ``nauty-geng``; pynauty ships no geng) generating
every connected graph with n vertices, 3(n-1)/2 - F/2 edges and minimum degree 2,
followed by a vectorised brute-force admissibility filter (every link subset S,
``3(|S|-1) - 2 e(S) >= 1``: one matrix product per batch of graphs), counts compared.
The brute force grows as 2^n: n <= 12 (at 14, geng's generation alone is timed).

Run: ``python benchmarks/bench_atlas.py [--repeat R] [--pyslvs PYTHON] [--geng]``.  Prints the
median wall time of each case, the count found, and the ratio to the target; with
``--pyslvs`` also times pyslvs's structural synthesis (run in that interpreter, e.g. a
separate venv) on the same simple-joint cases, side by side in the same run.
"""

from __future__ import annotations

import argparse
import json
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
    args = ap.parse_args()
    if args.geng:
        race_geng(args.repeat, tuple(int(x) for x in args.sizes.split(",")), args.verify)
    if args.mj12:
        run_mj12(args.repeat)
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


def _rigid_test(n: int, F: int) -> tuple[object, object]:
    """(inside, need) for the vertex subsets the filter tests, as float32 matrices.

    A subset S of links is rigid when 2 e(S) >= 3 |S| - 3 (e(S): joints inside S).
    In geng's output (simple, triangle-free, minimum degree 2) |S| <= 4 never is, and
    for F = 1 (2e = 3n - 4) neither are |S| >= n - 2 (two removed links take >= 3
    joints with them): the filter tests the sizes between, all of them.
    """
    from itertools import combinations

    import numpy as np

    top = n - 3 if F == 1 else n - 1
    subsets = [
        sum(1 << v for v in c) for s in range(5, top + 1) for c in combinations(range(n), s)
    ]
    member = (np.array(subsets)[:, None] >> np.arange(n)) & 1
    pairs = [(i, j) for j in range(n) for i in range(j)]  # graph6's bit order
    inside = np.array([member[:, i] & member[:, j] for i, j in pairs], dtype=np.float32)
    need = ((3 * member.sum(axis=1) - 3) / 2).astype(np.float32)
    return inside, need


_TEST: dict[tuple[int, int], tuple[object, object]] = {}


def _filter_block(job: tuple[int, int, bytes, bool]) -> tuple[int, int, list[bytes]]:
    """(graphs, admissible ones, their graph6 lines if asked) of a block of geng's output."""
    import numpy as np

    n, F, block, keep = job
    if (n, F) not in _TEST:
        _TEST[n, F] = _rigid_test(n, F)
    inside, need = _TEST[n, F]
    raw = np.frombuffer(block, dtype=np.uint8)
    width = block.index(b"\n") + 1
    raw = raw.reshape(-1, width)
    six = raw[:, 1:-1] - 63  # graph6: n, then the upper triangle, 6 bits a byte
    bits = np.unpackbits(six[:, :, None], axis=2)[:, :, 2:].reshape(len(raw), -1)
    X = bits[:, : n * (n - 1) // 2].astype(np.float32)
    ok = np.ones(len(raw), dtype=bool)
    with np.errstate(all="ignore"):
        for lo in range(0, len(raw), 1024):
            joints_inside = X[lo : lo + 1024] @ inside  # e(S), every graph and subset
            ok[lo : lo + 1024] = ~(joints_inside >= need - 0.25).any(axis=1)
    lines = [bytes(raw[k, :-1]) for k in np.nonzero(ok)[0]] if keep else []
    return len(raw), int(ok.sum()), lines


def _one_blas_thread() -> None:
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def geng_admissible(F: int, n: int, workers: int = 2, keep: bool = False):  # type: ignore[no-untyped-def]
    """The independent enumerator: geng generates the simple-joint candidates (connected,
    biconnected -C: F = 1 chains are never fractionated; triangle-free -t: a triangle
    is a rigid sub-chain; minimum degree 2; 3(n-1)/2 - F/2 joints), a pool of
    ``workers`` processes filters geng's stream block by block (one float32 matrix
    product per 1024 graphs).  Returns (graphs, admissible, their graph6 lines if
    ``keep``)."""
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


def race_geng(repeat: int, sizes: tuple[int, ...], verify: bool) -> None:
    import shutil
    import time

    from mjstruct.synthesis.atlas import chain_code
    from timing import race

    if shutil.which(GENG) is None:
        print(f"{GENG}: not installed (apt-get install nauty): nothing to race")
        return
    print(f"simple-joint atlas, F = 1, wall time, medians of {repeat} rotations (load {_load()}):")
    print("  mjstruct: atlas(1, n, workers=2)")
    print("  peer: geng -Ct -d2 streaming into a vectorised rigid-subset filter on 2 processes")
    print(
        f"{'n':>3} {'mjstruct s':>11} {'geng+filter s':>14} {'ratio':>6} {'goal':>5} "
        f"{'chains':>8} {'peer':>8} {'geng graphs':>12}"
    )
    for n in sizes:
        got: dict[str, object] = {}

        def ours(n: int = n, got: dict[str, object] = got) -> None:
            got["ours"] = atlas(1, n, workers=2, limit=None)

        def peer(n: int = n, got: dict[str, object] = got) -> None:
            got["peer"] = geng_admissible(1, n, workers=2)

        t_ours, t_peer = race([ours, peer], repeat)
        a = got["ours"]
        graphs, count, _ = got["peer"]  # type: ignore[misc]
        goal = f"{GOAL_GENG:5.1f}" if n == max(sizes) else f"{'-':>5}"
        flag = "" if a.count == count else "  COUNTS DIFFER"  # type: ignore[attr-defined]
        print(
            f"{n:3d} {t_ours:11.2f} {t_peer:14.2f} {t_ours / t_peer:6.2f} {goal} "
            f"{a.count:8d} {count:8d} {graphs:12d}{flag}"  # type: ignore[attr-defined]
        )
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


def _load() -> str:
    import os

    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


MJ12_CHILD = r"""
import json, resource, sys, time
from mjstruct.synthesis.atlas import atlas
t = time.perf_counter()
a = atlas(1, 12, mj=True, workers=2)
dt = time.perf_counter() - t
self_ = resource.getrusage(resource.RUSAGE_SELF)
kids = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"seconds": dt, "count": a.count,
    "cpu": self_.ru_utime + self_.ru_stime + kids.ru_utime + kids.ru_stime,
    "parent_mb": self_.ru_maxrss / 1024, "worker_mb": kids.ru_maxrss / 1024}))
"""


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


def run_mj12(repeat: int) -> None:
    """The MJ atlas F = 1, 12 links, 2 workers, each run in a fresh process whose tree's
    memory is sampled every 20 ms: wall time, peak Σ PSS (each shared page counted
    once, split between the processes sharing it), and each process's peak RSS."""
    import statistics
    import sys
    import time

    print(f"MJ atlas F = 1, n = 12, 2 workers, {repeat} runs in fresh processes (load {_load()}):")
    print(
        f"{'run':>4} {'wall s':>7} {'cpu s':>6} {'chains':>7} {'peak PSS MB':>12} "
        f"{'parent RSS':>11} {'worker RSS':>11}"
    )
    walls, peaks = [], []
    for k in range(repeat):
        child = subprocess.Popen(
            [sys.executable, "-c", MJ12_CHILD], stdout=subprocess.PIPE, text=True
        )
        peak = 0.0
        while child.poll() is None:
            peak = max(peak, _tree_memory(child.pid)[0])
            time.sleep(0.02)
        r = json.loads(child.stdout.read())  # type: ignore[union-attr]
        walls.append(r["seconds"])
        peaks.append(peak)
        print(
            f"{k + 1:4d} {r['seconds']:7.1f} {r['cpu']:6.1f} {r['count']:7d} {peak:12.0f} "
            f"{r['parent_mb']:11.0f} {r['worker_mb']:11.0f}"
        )
    t, m = statistics.median(walls), statistics.median(peaks)
    print(
        f"median {t:.1f} s (goal {GOAL_MJ12_S:.0f} s: ratio {t / GOAL_MJ12_S:.2f}), "
        f"peak PSS {m:.0f} MB (goal {GOAL_MJ12_MB:.0f} MB: ratio {m / GOAL_MJ12_MB:.2f})"
    )


if __name__ == "__main__":
    main()
