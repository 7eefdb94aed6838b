"""Timing shared by the benchmark scripts: medians of repeats, and races that run
several functions in rotation so the shared machine's load hits them alike."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any


def median_time(fn: Callable[[], Any], repeat: int = 5, number: int = 1) -> tuple[float, Any]:
    """Median seconds per call over ``repeat`` runs of ``number`` calls, and the last result."""
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            result = fn()
        times.append((time.perf_counter() - t0) / number)
    return statistics.median(times), result


def race(
    fns: Sequence[Callable[[], Any]],
    repeat: int,
    clock: Callable[[], float] = time.perf_counter,
) -> list[float]:
    """Median seconds of each function, run in rotation after one warm-up call each.

    ``clock``: wall time by default; ``time.process_time`` gives the CPU time of the
    process, which other jobs on a loaded machine disturb less.
    """
    for fn in fns:
        fn()
    out: list[list[float]] = [[] for _ in fns]
    for _ in range(repeat):
        for k, fn in enumerate(fns):
            t0 = clock()
            fn()
            out[k].append(clock() - t0)
    return [statistics.median(x) for x in out]
