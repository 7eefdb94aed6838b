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
    args = ap.parse_args()
    if args.geng:
        race_geng(args.repeat)
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


def geng_admissible(F: int, n: int) -> tuple[int, int]:
    """(graphs geng generated, admissible ones): the independent enumerator."""
    import numpy as np

    e = (3 * (n - 1) - F) // 2
    out = subprocess.run(
        [GENG, "-c", "-d2", "-q", str(n), f"{e}:{e}"], capture_output=True, check=True
    ).stdout
    raw = np.frombuffer(out, dtype=np.uint8).reshape(-1, len(out.split(b"\n", 1)[0]) + 1)
    six = raw[:, 1:-1].astype(np.uint8) - 63  # graph6: n, then the upper triangle
    bits = np.unpackbits(six[:, :, None], axis=2)[:, :, 2:].reshape(len(raw), -1)
    pairs = [(i, j) for j in range(n) for i in range(j)]  # graph6's column order
    X = bits[:, : len(pairs)].astype(np.float32)
    subsets = np.arange(1 << n)
    member = (subsets[:, None] >> np.arange(n)) & 1
    inside = np.array([member[:, i] & member[:, j] for i, j in pairs], dtype=np.float32)
    size = member.sum(axis=1)
    big = size >= 2
    limit = np.where(big, (3 * (size - 1) - 1) / 2, np.inf)  # e(S) at most this
    ok = np.ones(len(raw), bool)
    for lo in range(0, len(raw), 4096):
        counts = X[lo : lo + 4096] @ inside  # e(S) for every graph and subset
        ok[lo : lo + 4096] = (counts <= limit[None, :] + 1e-9).all(axis=1)
    return len(raw), int(ok.sum())


GENG = "nauty-geng"


def race_geng(repeat: int) -> None:
    import shutil

    if shutil.which(GENG) is None:
        print(f"{GENG}: not installed (apt-get install nauty): nothing to race")
        return
    print("simple-joint atlas, F = 1: mjstruct (2 workers) against geng + numpy filter")
    print(f"{'n':>3} {'mjstruct s':>11} {'geng+filter s':>14} {'ratio':>6} {'counts':>16}")
    for n in (10, 12):
        t_ours, a = median_time(partial(atlas, 1, n, workers=2), repeat)
        t_peer, (graphs, count) = median_time(partial(geng_admissible, 1, n), repeat)
        print(
            f"{n:3d} {t_ours:11.3f} {t_peer:14.3f} {t_ours / t_peer:6.1f} "
            f"{a.count:>7}/{count:<7} of {graphs} graphs"
        )
    t0 = median_time(
        lambda: subprocess.run([GENG, "-c", "-d2", "-u", "14", "19:19"], capture_output=True), 1
    )[0]
    print(f" 14 geng's generation alone (no filter): {t0:.2f} s; goal: mjstruct within 1.2x")


if __name__ == "__main__":
    main()
