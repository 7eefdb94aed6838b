"""nauty in process or in a worker: where the threshold sits, and the quotients.

Prints, side by side in one run (medians, CPU time of this process for nauty in
process, wall time for the worker's round trip):

1. nauty in process on the hardest graph families found, at one vertex below
   ``WORKER_VERTICES`` (the largest graph nauty is run on in process, where no signal
   is received while it runs): a star of pendant links, pendant two-link tails,
   triangles with a tail on one link (the signal test's graph), a ring, k paths of
   three binary links between two links with the quotient off. Goal: well under 0.1 s.
2. The worker's round trip on a small graph next to the same call in process (what
   a graph at the threshold pays for being interruptible).
3. k paths of one binary link between links 0 and 1 (the parallel-paths attack):
   nauty on the whole graph next to ``certificate_of`` (the chain quotient), k = 300.

Run: ``python benchmarks/bench_nauty_worker.py [REPEAT]`` (default 7)
"""

from __future__ import annotations

import itertools
import sys
import time
from collections.abc import Callable

import pynauty

from mjstruct.structure import isomorphism as iso
from timing import race

Graph = tuple[int, list[list[int]]]


def star(v: int) -> Graph:
    n = (v + 1) // 2
    return n, [[0, k] for k in range(1, n)]


def tails(v: int) -> Graph:
    h = (v - 1) // 4
    return 1 + 2 * h, [[0, 1 + k] for k in range(h)] + [[1 + k, 1 + h + k] for k in range(h)]


def blocks(v: int) -> Graph:
    k = (v - 1) // 8
    joints = []
    for i in range(k):
        a, b, c = 1 + 3 * i, 2 + 3 * i, 3 + 3 * i
        joints += [[0, a], [a, b], [b, 0], [a, c], [c, 0]]
    return 1 + 3 * k, joints


def ring(v: int) -> Graph:
    n = v // 2
    return n, [[k, (k + 1) % n] for k in range(n)]


def paths(count: int, length: int = 1) -> Graph:
    joints: list[list[int]] = []
    n = 2
    for _ in range(count):
        chain = [0, *range(n, n + length), 1]
        n += length
        joints += [[a, b] for a, b in itertools.pairwise(chain)]
    return n, joints


def in_process(g: Graph) -> Callable[[], object]:
    n, joints = g
    graph = iso.nauty_graph(n, joints)
    return lambda: pynauty.certificate(graph)


def main(repeat: int) -> None:
    v = iso.WORKER_VERTICES - 1
    print(f"1. nauty in process at {v} vertices (WORKER_VERTICES - 1), CPU seconds")
    families = {
        "star of pendant links": star(v),
        "pendant two-link tails": tails(v),
        "triangles with a tail": blocks(v),
        "ring": ring(v),
        "paths of 3 links (no quotient)": paths((v - 2) // 7, 3),
    }
    times = race([in_process(g) for g in families.values()], repeat, time.process_time)
    for (name, (n, joints)), t in zip(families.items(), times, strict=True):
        print(f"   {name:32s} V = {n + len(joints):4d}  {t * 1e3:7.2f} ms")
    print(f"   worst {max(times) * 1e3:.1f} ms (goal: under 100 ms)")

    n, joints = star(100)
    args = ("certificate", n, joints, None)
    worker, here = race(
        [lambda: iso._in_worker(args), lambda: iso._nauty(*args)], repeat, time.perf_counter
    )
    print("2. worker round trip against in process, star of 100 links, wall seconds")
    print(f"   worker {worker * 1e3:.1f} ms, in process {here * 1e3:.2f} ms")

    k = 300
    n, joints = paths(k)
    colours = [range(n), range(n, n + len(joints))]
    whole, quotient = race(
        [in_process((n, joints)), lambda: iso.certificate_of(n, joints, colours)],
        repeat,
        time.process_time,
    )
    print(f"3. {k} paths of one binary link between links 0 and 1, CPU seconds")
    print(f"   whole graph {whole * 1e3:.1f} ms, quotient {quotient * 1e3:.2f} ms")
    print(f"   ratio {whole / quotient:.0f}x (the whole graph grows as k^3: 1500 took ~1 min)")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
