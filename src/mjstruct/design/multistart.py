"""The default global stage: a large screened sample, its basins, a local solve in each.

Owns :func:`run_multistart`, one restart of the ``multistart`` method (the default
``solver.method``; scipy's differential evolution stays available as ``"de"``,
:func:`mjstruct.design.search.run_de`):

1. **screen**: ``solver.screen`` Latin hypercube samples of the global variables
   (times 2^k on restart k: later restarts look wider) and the task's starting
   designs, judged in batched kinematics calls (:meth:`FitProblem.assess`, a few
   thousand candidates per call);
2. **basins**: the candidates ranked (feasible ones by energy, then the others by
   their worst margin) and thinned greedily so that no two kept ones lie within
   ``BASIN_RADIUS`` of the bounds' width of each other (max norm): one start per
   basin, up to ``solver.local_starts`` (times 2^k);
3. **local**: scipy's ``least_squares`` (the problem's residuals and Jacobian) from
   every starting design of the task first (so the result is never worse than a
   feasible start) and then from each basin's best, best first; each result is
   judged by the kinematics (:meth:`FitProblem.finish`).

A ``deadline`` (``time.perf_counter()`` value) stops the local solves early: the run
returns what it has (an anytime search).

Examples
--------
>>> import numpy as np
>>> X = np.array([[0.0, 0.0], [0.01, 0.0], [0.5, 0.5], [0.52, 0.5], [1.0, 0.0]])
>>> basins(X, np.array([3.0, 1.0, 2.0, 5.0, 4.0]), np.zeros(2), np.ones(2), 3)
[1, 2, 4]
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from mjstruct.design.problem import (
    LOCAL_EVALUATIONS,
    MARGIN_SLACK,
    FitProblem,
    Outcome,
    Progress,
    Run,
    latin_hypercube,
    local_solve,
)
from mjstruct.typing import FloatArray, IntArray

#: two screened candidates closer than this (max norm, relative to the bounds' width)
#: share a basin: only the better one starts a local solve
BASIN_RADIUS = 0.05
#: the best local solves of a restart that go on, and for how many times as long
POLISHED = 3
POLISH = 6
#: frames (candidates × driver samples) per batched screening call: bounds the memory
#: of one call (a few tens of MB)
SCREEN_FRAMES = 400_000


def screen(problem: FitProblem, X: FloatArray, samples: int) -> tuple[FloatArray, FloatArray]:
    """Energy and worst margin of every row of ``X``, in calls of at most
    ``SCREEN_FRAMES`` frames."""
    chunk = max(1, SCREEN_FRAMES // max(samples, 1))
    energy, worst = [], []
    for i in range(0, len(X), chunk):
        a = problem.assess(X[i : i + chunk])
        problem.evaluations += len(X[i : i + chunk])
        w = np.full(len(a.energy), np.inf)
        for v in a.margins.values():
            w = np.minimum(w, v)
        energy.append(a.energy)
        worst.append(w)
    return np.concatenate(energy), np.concatenate(worst)


def ranking(energy: FloatArray, worst: FloatArray) -> IntArray:
    """Feasible candidates by energy first, then the others by their worst margin."""
    feasible = worst >= MARGIN_SLACK
    key = np.where(feasible & np.isfinite(energy), energy, np.inf)
    out: IntArray = np.lexsort((-worst, key))
    return out


def basins(
    X: FloatArray, order_key: FloatArray, lo: FloatArray, hi: FloatArray, count: int
) -> list[int]:
    """Up to ``count`` rows of ``X``, best ``order_key`` first, no two within
    ``BASIN_RADIUS`` of the bounds' width of each other (max norm)."""
    width = np.maximum(hi - lo, 1e-300)
    U = (X - lo) / width
    kept: list[int] = []
    for i in np.argsort(order_key, kind="stable"):
        if len(kept) >= count:
            break
        if kept and np.min(np.max(np.abs(U[kept] - U[i]), axis=1)) <= BASIN_RADIUS:
            continue
        kept.append(int(i))
    return kept


def run_multistart(
    problem: FitProblem,
    seed: int,
    solver: Mapping[str, Any],
    progress: Progress | None = None,
    deadline: float | None = None,
    round_index: int = 0,
) -> Run:
    """One restart of the multistart search (see the module text); restart
    ``round_index`` screens and solves 2^round_index times as many."""
    t0 = time.perf_counter()
    problem.evaluations = 0
    lo, hi = problem.bounds()
    grow = 2 ** min(round_index, 8)
    starts = np.array([np.clip(x, lo, hi) for x in problem.starts()])
    rng = np.random.default_rng(seed)
    n = int(solver["screen"]) * grow
    X = np.vstack([starts, lo + (hi - lo) * latin_hypercube(n, len(lo), rng)])
    energy, worst = screen(problem, X, int(problem.screen_frames))
    order = ranking(energy, worst)
    rank = np.empty(len(X))
    rank[order] = np.arange(len(X))
    count = int(solver["local_starts"]) * grow
    picked = basins(X[len(starts) :], rank[len(starts) :], lo, hi, count)
    queue = list(range(len(starts))) + [len(starts) + i for i in picked]
    history: list[tuple[int, float, float]] = []
    outcomes: list[Outcome] = []
    best = math.inf
    for x in starts:  # the starts' own verdicts: never worse than them
        o = problem.finish(x, local=False)
        outcomes.append(o)
        if o.feasible:
            best = min(best, o.objective)
    history.append((problem.evaluations, time.perf_counter() - t0, best))
    # many untimed targets: the basins are solved on a thinned set of them (the cost of
    # a solve then does not grow with their number); the best go on with all of them
    coarse = problem.coarse()
    trial: list[Outcome] = []
    for k, i in enumerate(queue):
        if deadline is not None and time.perf_counter() > deadline and k > 0:
            break
        solved = local_solve(coarse, X[i])
        if solved is not None:
            trial.append(solved)
            if coarse is problem:
                outcomes.append(solved)
                if solved.feasible:
                    best = min(best, solved.objective)
        if coarse is not problem:  # its evaluations count as the problem's
            problem.evaluations += coarse.evaluations
            coarse.evaluations = 0
        history.append((problem.evaluations, time.perf_counter() - t0, best))
        if progress is not None:
            progress(k + 1, len(queue))
    # the most promising basins get the rest: their solves go on, POLISH times longer
    trial.sort(key=lambda o: (not o.feasible, o.objective))
    for o in trial[:POLISHED]:
        if deadline is not None and time.perf_counter() > deadline:
            break
        assert o.local is not None
        if coarse is problem:
            more = local_solve(problem, X[0], POLISH * LOCAL_EVALUATIONS, z=o.local)
        else:
            more = local_solve(problem, o.local[: len(lo)], POLISH * LOCAL_EVALUATIONS)
        if more is not None:
            outcomes.append(more)
            if more.feasible:
                best = min(best, more.objective)
        history.append((problem.evaluations, time.perf_counter() - t0, best))
    return Run(tuple(outcomes), tuple(history), problem.evaluations, time.perf_counter() - t0)
