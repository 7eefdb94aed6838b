"""The search shared by the fitting tasks: global stage, local stage, verdict.

Owns :func:`solve`, which runs ``restarts`` searches of the ``solver.method`` a task
names and keeps the best feasible verdict, and :func:`run_once`, one restart:

1. **global**: ``multistart`` (the default, :mod:`mjstruct.design.multistart`: a
   screened sample, its basins, a local solve in each) or ``de``: scipy's
   ``differential_evolution`` (:func:`run_de`; vectorised: each generation's trial
   population is one :meth:`~mjstruct.design.problem.FitProblem.assess` call, so one
   batched kinematics evaluation; constraints by its feasibility rules on the task's
   margins), started from the starting designs and a screened Latin hypercube;
2. **local**: :func:`~mjstruct.design.problem.local_solve` (scipy's
   ``least_squares`` on the targets' residuals, the driver values of the targets
   variables where they are free) from the global stage's best members and from
   every starting design;
3. **verdict**: :meth:`~mjstruct.design.problem.FitProblem.finish` moves each
   stage's best with the kinematics itself (:mod:`mjstruct.design.verify`); the best
   feasible one wins, so a feasible start bounds the result.

``restarts`` independent runs (seeds spawned from the task's seed, so the same seed
gives the same design whatever the number of workers) run in this process, on the
process pool the atlas uses (``workers``) or on a Dask cluster (``scheduler``).
``budget`` makes the run anytime (see :func:`solve`).

Examples
--------
>>> import numpy as np
>>> s = seeds(7, 3)
>>> s == seeds(7, 3), len(set(s))
(True, 3)
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mjstruct.design.problem import (
    LOCAL_STARTS,
    MARGIN_SLACK,
    Assessment,
    FitProblem,
    Outcome,
    Progress,
    Run,
    latin_hypercube,
    local_solve,
)
from mjstruct.design.result import DesignResult
from mjstruct.errors import NumericalError
from mjstruct.typing import FloatArray


def seeds(seed: int | None, count: int) -> list[int]:
    """``count`` independent seeds derived from ``seed`` (deterministic)."""
    ss = np.random.SeedSequence(seed)
    return [int(s.generate_state(1)[0]) for s in ss.spawn(count)]


@dataclass
class _Batch:
    """The objective and the constraints of scipy's vectorised DE from one evaluation
    per trial population (scipy asks for the constraints first, then the energies of
    the feasible members)."""

    problem: FitProblem
    names: list[str] = field(default_factory=list)
    cache: dict[bytes, tuple[float, FloatArray]] = field(default_factory=dict)
    best: float = math.inf

    def _run(self, X: FloatArray) -> Assessment:
        a = self.problem.assess(X)
        self.problem.evaluations += X.shape[0]
        ok = np.ones(X.shape[0], bool)
        for v in a.margins.values():
            ok &= v >= MARGIN_SLACK
        if ok.any():
            self.best = min(self.best, float(np.min(np.where(ok, a.energy, np.inf))))
        return a

    def _recall(self, row: FloatArray) -> tuple[float, FloatArray] | None:
        """A row's cached energy and margins, made the most recent (least recently
        asked rows go first: scipy asks for its best member after every generation,
        which may be many generations old)."""
        key = row.tobytes()
        hit = self.cache.pop(key, None)
        if hit is not None:
            self.cache[key] = hit
        return hit

    def constraints(self, xT: FloatArray) -> FloatArray:
        X = np.atleast_2d(xT.T) if xT.ndim == 2 else xT[None, :]
        rows = [self._recall(row) for row in X]
        if all(r is not None for r in rows):  # scipy asking again (its callback's best)
            out = np.array([r[1] for r in rows if r is not None]).T
        else:
            a = self._run(X)
            out = np.array([a.margins[k] for k in self.names])
            for i, (row, e) in enumerate(zip(X, a.energy, strict=True)):
                self.cache[row.tobytes()] = (float(e), out[:, i])
            for key in list(self.cache)[: max(0, len(self.cache) - 4 * len(X))]:
                del self.cache[key]  # keep the last generations' rows only
        return out if xT.ndim == 2 else out[:, 0]

    def energy(self, xT: FloatArray) -> FloatArray:
        X = np.atleast_2d(xT.T)
        out = np.empty(X.shape[0])
        missing = []
        for i, row in enumerate(X):
            hit = self._recall(row)
            if hit is None:
                missing.append(i)
            else:
                out[i] = hit[0]
        if missing:
            a = self._run(X[missing])
            out[missing] = a.energy
        return np.where(np.isfinite(out), out, 1e300)


def run_once(
    problem: FitProblem,
    seed: int,
    solver: Mapping[str, Any],
    progress: Progress | None = None,
    deadline: float | None = None,
    round_index: int = 0,
) -> Run:
    """One restart of the search ``solver["method"]`` names (``multistart``:
    :mod:`mjstruct.design.multistart`; ``de``: differential evolution, below) from
    ``seed``; past ``deadline`` (a ``time.perf_counter()`` value) it stops starting
    new work and returns what it has."""
    from threadpoolctl import threadpool_limits

    # one BLAS thread: the local stage's small decompositions (an SVD of a few hundred
    # rows per step) ran 30x slower in CPU time on two threads of a busy machine
    with threadpool_limits(1):
        if str(solver.get("method", "de")) == "multistart":
            from mjstruct.design.multistart import run_multistart

            return run_multistart(problem, seed, solver, progress, deadline, round_index)
        return run_de(problem, seed, solver, progress, deadline)


def run_de(
    problem: FitProblem,
    seed: int,
    solver: Mapping[str, Any],
    progress: Progress | None = None,
    deadline: float | None = None,
) -> Run:
    """One global search by differential evolution from ``seed``, the local stage
    from its best members and from every starting design, the verdicts."""
    from scipy.optimize import NonlinearConstraint, differential_evolution

    t0 = time.perf_counter()
    problem.evaluations = 0
    lo, hi = problem.bounds()
    x0 = np.array([np.clip(x, lo, hi) for x in problem.starts()])
    first = problem.assess(x0[:1])
    batch = _Batch(problem, names=sorted(first.margins))
    history: list[tuple[int, float, float]] = []
    generations = int(solver["generations"])
    step = [0]

    def record(*_: Any) -> bool:
        step[0] += 1
        history.append(
            (
                problem.evaluations,
                time.perf_counter() - t0,
                problem.energy_to_objective(batch.best),
            )
        )
        if progress is not None:
            progress(min(step[0], generations), generations)
        return deadline is not None and time.perf_counter() > deadline

    kwargs: dict[str, Any] = {}
    if batch.names:
        kwargs["constraints"] = NonlinearConstraint(batch.constraints, 0.0, np.inf)
    members = int(solver["population"]) * len(lo)
    init = screened_start(problem, lo, hi, x0, members, seed)
    de = differential_evolution(
        batch.energy,
        list(zip(lo, hi, strict=True)),
        init=init,
        seed=seed,
        maxiter=generations,
        tol=float(solver["tol"]),
        polish=False,
        updating="deferred",
        vectorized=True,
        callback=record,
        strategy=str(solver.get("strategy", "rand1bin")),
        **kwargs,
    )
    outcomes = [problem.finish(np.asarray(de.x, float), local=False)]
    outcomes += [problem.finish(x, local=False) for x in x0]  # never worse than a start
    local = _local_starts(problem, de, LOCAL_STARTS) + list(x0)
    for k, x in enumerate(local):
        if deadline is not None and time.perf_counter() > deadline and k > 0:
            break
        o = local_solve(problem, x)
        if o is not None:
            outcomes.append(o)
    best = min((o for o in outcomes if o.feasible), key=lambda o: o.objective, default=None)
    if best is not None:
        history.append((problem.evaluations, time.perf_counter() - t0, best.objective))
    if progress is not None:
        progress(generations, generations)
    return Run(tuple(outcomes), tuple(history), problem.evaluations, time.perf_counter() - t0)


#: candidates screened per member of the first population
SCREEN = 10


def screened_start(
    problem: FitProblem, lo: FloatArray, hi: FloatArray, x0: FloatArray, members: int, seed: int
) -> FloatArray:
    """The first population: the starting designs and the best of ``SCREEN`` times
    ``members`` Latin hypercube samples, judged in one batched call (feasible ones by
    energy first, then the others by their worst margin)."""
    members = max(members, 5)
    sample = latin_hypercube(SCREEN * members, len(lo), np.random.default_rng(seed))
    X = np.vstack([np.atleast_2d(x0), lo + (hi - lo) * sample])
    a = problem.assess(X)
    problem.evaluations += len(X)
    worst = np.full(len(X), np.inf)
    for v in a.margins.values():
        worst = np.minimum(worst, v)
    feasible = worst >= MARGIN_SLACK
    key = np.where(feasible, a.energy, np.inf)
    order = np.lexsort((-worst, key))  # energy among the feasible, then least violation
    keep = list(range(len(np.atleast_2d(x0))))  # every start belongs to the population
    keep += [int(i) for i in order if i >= len(keep)][: members - len(keep)]
    init: FloatArray = X[keep]
    return init


def _local_starts(problem: FitProblem, de: Any, count: int) -> list[FloatArray]:
    """The global stage's best member and the next best distinct feasible members of
    its last population (distinct: apart by more than 1e-3 of the bounds' width)."""
    pop = np.asarray(de.population, float)
    a = problem.assess(pop)
    problem.evaluations += len(pop)
    ok = np.ones(len(pop), bool)
    for v in a.margins.values():
        ok &= v >= MARGIN_SLACK
    order = np.argsort(np.where(ok, a.energy, np.inf), kind="stable")
    lo, hi = problem.bounds()
    width = np.maximum(hi - lo, 1e-300)
    starts = [np.asarray(de.x, float)]
    for i in order:
        if len(starts) >= count or not ok[i]:
            break
        x = pop[i]
        if all(np.max(np.abs(x - s) / width) > 1e-3 for s in starts):
            starts.append(x)
    return starts


def _restart_bar(
    progress: Progress, k: int, restarts: int, t0: float, budget: float | None
) -> Progress:
    """Restart k's progress as the whole run's: its share of the restarts, or of the
    budget's time."""

    def bar(i: int, n: int) -> None:
        if budget is None:
            progress(k * n + i, restarts * n)
        else:
            spent = min(time.perf_counter() - t0, budget)
            progress(int(1000 * spent / budget), 1000)

    return bar


def _run_task(task: tuple[FitProblem, int, Mapping[str, Any], float | None, int]) -> Run:
    problem, seed, solver, budget, k = task
    deadline = None if budget is None else time.perf_counter() + budget
    return run_once(problem, seed, solver, deadline=deadline, round_index=k)


def solve(
    problem: FitProblem,
    seed: int | None,
    solver: Mapping[str, Any],
    workers: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
    budget: float | None = None,
) -> DesignResult:
    """Run ``restarts`` searches (restart k of ``multistart`` screens 2^k times as
    many); the best feasible verdict is the design.

    ``budget`` (seconds, wall clock): an anytime run.  In this process, restarts go on
    (k = 0, 1, 2, ..., whatever ``restarts`` says) until the budget is spent, each
    stopping its local solves or generations at the deadline; on workers, each of the
    ``restarts`` runs gets the whole budget.  The design is then the best feasible one
    found in the time, which depends on the machine's speed.

    Raises
    ------
    NumericalError
        no run found a feasible design (the message starts ``no feasible design:``
        and gives the best constraint violation and why the kinematics refused it).
    """
    t0 = time.perf_counter()
    restarts = int(solver["restarts"])
    runs: list[Run] = []
    if workers <= 1 and scheduler is None:
        deadline = None if budget is None else t0 + budget
        k = 0
        while k < restarts or (deadline is not None and time.perf_counter() < deadline):
            bar = None if progress is None else _restart_bar(progress, k, restarts, t0, budget)
            s = seeds(seed, k + 1)[k]
            runs.append(run_once(problem, s, solver, bar, deadline, k))
            k += 1
            if deadline is not None and time.perf_counter() >= deadline:
                break
    else:
        from mjstruct.synthesis.parallel import run_tasks

        subseeds = seeds(seed, restarts)
        tasks = [(problem, s, solver, budget, k) for k, s in enumerate(subseeds)]
        runs = list(run_tasks(_run_task, tasks, workers, progress, scheduler))
    restarts = len(runs)
    outcomes = [o for r in runs for o in r.outcomes]
    history: list[tuple[int, float, float]] = []
    evals, secs, best = 0, 0.0, math.inf
    for r in runs:  # one record: the restarts one after another
        for k, t, f in r.history:
            best = min(best, f)
            history.append((evals + k, secs + t, best))
        evals += r.evaluations
        secs += r.seconds
    feasible = [o for o in outcomes if o.feasible]
    if not feasible:
        least = min(outcomes, key=lambda o: (o.violation, o.objective))
        why = f"; {least.reason}" if least.reason else ""
        raise NumericalError(
            f"no feasible design: best constraint violation {least.violation:.3g} "
            f"({_worst(least)}){why}"
        )
    best_o = min(feasible, key=lambda o: o.objective)
    details = dict(best_o.details)
    details["restarts"] = restarts
    details["stage"] = details.get("stage", "local")
    return DesignResult(
        best_o.mechanism,
        problem.kind,
        best_o.objective,
        True,
        best_o.errors,
        evals,
        time.perf_counter() - t0,
        seed,
        tuple(history),
        dict(best_o.margins),
        details,
    )


def _worst(o: Outcome) -> str:
    finite = {k: v for k, v in o.margins.items() if math.isfinite(v)}
    if not finite:
        return "no margin"
    k = min(finite, key=finite.__getitem__)
    return f"{k} margin {finite[k]:.3g}"
