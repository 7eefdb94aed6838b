"""Path synthesis of four-bars: mjstruct synthesize against a plain differential
evolution on the textbook closed-form objective, on standard problems from the
literature; and the cost of one batched evaluation of a population.

Problems (targets as given in the literature; bounds chosen here, see
docs/synthesis-design.md):

* ``line6``: six collinear points (20, 20) … (20, 45), untimed;
* ``curve18``: the 18-point closed curve of [Kunjur 1997] as used by [Cabrera 2002],
  untimed;
* ``ellipse10``: ten points on an ellipse [Ullah 1997], untimed;
* ``timed5``: five points (20, 20) … (20, 40) at crank angles π/6 … π/2 from the frame
  line (frame angle free), timed.

Each is a Grashof crank-rocker with the coupler point C.  The baseline is scipy's
``differential_evolution`` with its defaults on the closed form used by the papers:
variables r1 (frame), r2 (crank), r3 (coupler), r4 (rocker), rcx, rcy (C in the
coupler's frame), θ0 (frame angle), x0, y0 (crank pivot) and, for untimed targets,
the crank angle θ2 of each target; the crank-rocker condition and the order of the
θ2 by penalties.  mjstruct gets the same targets and requirement as a task file.
Both answers are scored alike: the sum of squared distances between the targets and
the coupler point where the design meets them (mjstruct's by its own verdict; the
baseline's by the closed form, kept only when it is a crank-rocker with its θ2 in
order, else reported infeasible).

Times are the CPU time of this process (``time.process_time``: both run in one
thread; other jobs on the shared machine disturb it less than the wall clock).

Run: ``python benchmarks/bench_synthesis.py [--seeds 5] [--problems line6,timed5]
[--batch-only] [--atlas] [--stages timed5] [--race [--limit SECONDS]]``.  ``--race``:
mjstruct against scipy's DE vectorised (``vectorized=True``, deferred updating) on a
vectorised closed form, CPU time to each problem's target (``TARGETS``; "never" when a
contender does not reach it) and the best objective against CPU time.  Prints per
problem and seed, then medians and the ratios (``--stages P``: only where mjstruct's
time goes on P).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from typing import Any

import numpy as np

PROBLEMS: dict[str, dict[str, Any]] = {
    "line6": {
        "targets": [(20.0, 20.0 + 5 * k) for k in range(6)],
        "timing": None,
        "r": (5.0, 60.0),
        "box": 60.0,
    },
    "curve18": {
        "targets": [
            (0.5, 1.1),
            (0.4, 1.1),
            (0.3, 1.1),
            (0.2, 1.0),
            (0.1, 0.9),
            (0.05, 0.75),
            (0.02, 0.6),
            (0.0, 0.5),
            (0.0, 0.4),
            (0.03, 0.3),
            (0.1, 0.25),
            (0.15, 0.2),
            (0.2, 0.3),
            (0.3, 0.4),
            (0.4, 0.5),
            (0.5, 0.7),
            (0.6, 0.9),
            (0.6, 1.0),
        ],
        "timing": None,
        "r": (0.05, 5.0),
        "box": 5.0,
    },
    "ellipse10": {
        "targets": [
            (20.0, 10.0),
            (17.66, 15.142),
            (11.736, 17.878),
            (5.0, 16.928),
            (0.60307, 12.736),
            (0.60307, 7.2638),
            (5.0, 3.0718),
            (11.736, 2.1215),
            (17.66, 4.8577),
            (20.0, 10.0),
        ],
        "timing": None,
        "r": (5.0, 80.0),
        "box": 80.0,
    },
    "timed5": {
        "targets": [(20.0, 20.0 + 5 * k) for k in range(5)],
        "timing": [math.pi / 6, math.pi / 4, math.pi / 3, 5 * math.pi / 12, math.pi / 2],
        "r": (5.0, 60.0),
        "box": 60.0,
    },
}

PENALTY = 1e4
#: the goals: per problem, mjstruct's median objective at most the plain DE's, in at
#: most this fraction of its median CPU time; one batched population call at most
#: this multiple of the sequential closed form's floor
TIME_GOAL = 0.1
BATCH_GOAL = 3.0


def verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


# -- the baseline: the textbook closed form ------------------------------------------


def closed_form(x: np.ndarray, theta2: np.ndarray) -> np.ndarray:
    """Coupler point C (complex) of the four-bar ``x`` at crank angles ``theta2``
    (from the frame line), open assembly; NaN where it does not assemble."""
    r1, r2, r3, r4, rcx, rcy, th0, x0, y0 = x[:9]
    A = r2 * np.exp(1j * theta2)
    e = r1 - A  # from A to O2 = (r1, 0)
    f = np.abs(e)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos_a = (r3 * r3 + f * f - r4 * r4) / (2 * r3 * f)
        alpha = np.arccos(cos_a)
    th3 = np.angle(e) + alpha
    C = A + (rcx + 1j * rcy) * np.exp(1j * th3)
    return complex(x0, y0) + C * np.exp(1j * th0)


def _grashof_violation(x: np.ndarray) -> float:
    r1, r2, r3, r4 = x[:4]
    s, lng = min(r1, r2, r3, r4), max(r1, r2, r3, r4)
    grashof = max(0.0, s + lng - (r1 + r2 + r3 + r4 - s - lng))
    crank = max(0.0, r2 - min(r1, r3, r4))
    return grashof + crank


def _order_violation(theta2: np.ndarray) -> float:
    """θ2 must increase once around the turn (in either sense, as the papers allow)."""
    steps = np.mod(np.diff(theta2), 2 * math.pi)
    forward = max(0.0, steps.sum() - 2 * math.pi)
    back = max(0.0, np.mod(-np.diff(theta2), 2 * math.pi).sum() - 2 * math.pi)
    return min(forward, back)


def baseline_objective(x: np.ndarray, targets: np.ndarray, timing: list[float] | None) -> float:
    theta2 = np.asarray(timing) if timing is not None else x[9:]
    C = closed_form(x, theta2)
    err = np.abs(C - targets) ** 2
    f = float(err.sum()) if np.isfinite(err).all() else 1e6
    v = _grashof_violation(x) + (0.0 if timing is not None else _order_violation(theta2))
    return f + PENALTY * v


def baseline_score(name: str, x: np.ndarray) -> tuple[float, bool]:
    """The sum of squared errors of the closed-form four-bar ``x`` at its own crank
    angles, and whether it is a crank-rocker with those angles in order."""
    p = PROBLEMS[name]
    targets = np.array([complex(*t) for t in p["targets"]])
    theta2 = np.asarray(p["timing"]) if p["timing"] is not None else x[9:]
    feasible = _grashof_violation(x) <= 1e-9 and (
        p["timing"] is not None or _order_violation(theta2) <= 1e-9
    )
    err = float((np.abs(closed_form(x, theta2) - targets) ** 2).sum())
    return (err if math.isfinite(err) else math.inf), bool(feasible)


def baseline_bounds(name: str) -> tuple[np.ndarray, list[tuple[float, float]]]:
    """The problem's targets (complex) and the closed form's variable bounds: r1...r4,
    rcx, rcy, the frame angle, x0, y0 and, untimed, one crank angle per target."""
    p = PROBLEMS[name]
    targets = np.array([complex(*t) for t in p["targets"]])
    lo, hi = p["r"]
    box = p["box"]
    bounds = [(lo, hi)] * 4 + [(-box, box)] * 2 + [(0.0, 2 * math.pi)] + [(-box, box)] * 2
    if p["timing"] is None:
        bounds += [(0.0, 2 * math.pi)] * len(targets)
    return targets, bounds


def baseline(
    name: str, seed: int, record: list[tuple[float, float, float]] | None = None
) -> tuple[np.ndarray, float]:
    """Plain differential evolution (scipy's defaults) on the closed form: its answer
    and its CPU seconds; ``record`` receives (CPU seconds, wall seconds, sum of squared
    errors of the best member, inf while it is infeasible) after each generation."""
    from scipy.optimize import differential_evolution

    p = PROBLEMS[name]
    targets, bounds = baseline_bounds(name)
    t0, w0 = time.process_time(), time.perf_counter()

    def note(xk: np.ndarray, convergence: float = 0.0) -> None:
        assert record is not None
        f, ok = baseline_score(name, xk)
        record.append((time.process_time() - t0, time.perf_counter() - w0, f if ok else math.inf))

    r = differential_evolution(
        baseline_objective,
        bounds,
        args=(targets, p["timing"]),
        seed=seed,
        callback=None if record is None else note,
    )
    return np.asarray(r.x, float), time.process_time() - t0


def run_baseline(name: str, seed: int) -> tuple[float, float, bool]:
    """Plain differential evolution (scipy's defaults): (sum of squared errors at its
    own crank angles, CPU seconds, whether it is a crank-rocker with them in order)."""
    x, seconds = baseline(name, seed)
    err, feasible = baseline_score(name, x)
    return err, seconds, feasible


# -- mjstruct ---------------------------------------------------------------------------


def task_for(name: str, solver: dict[str, int] | None = None) -> dict[str, Any]:
    """The problem as a task file: a crank-rocker started near the targets."""
    p = PROBLEMS[name]
    t = np.array(p["targets"])
    c = t.mean(axis=0)
    s = float(np.ptp(t, axis=0).max())
    O1 = c + s * np.array([-0.6, -0.8])
    A = O1 + 0.25 * s * np.array([0.5, 0.866])
    B = O1 + s * np.array([0.9, 0.7])
    O2 = O1 + s * np.array([1.0, 0.0])
    C = (A + B) / 2 + s * np.array([-0.2, 0.4])
    box = p["box"]
    reach = box + p["r"][1]
    mech = {
        "name": f"{name}-start",
        "frame": "0",
        "drivers": ["O1"],
        "joints": [
            {"id": "O1", "links": ["0", "1"], "at": O1.tolist()},
            {"id": "A", "links": ["1", "2"], "at": A.tolist()},
            {"id": "B", "links": ["2", "3"], "at": B.tolist()},
            {"id": "O2", "links": ["3", "0"], "at": O2.tolist()},
        ],
        "points": [{"id": "C", "link": "2", "at": C.tolist()}],
    }
    far = [[-reach, -reach], [reach, reach]]
    task: dict[str, Any] = {
        "task": "path",
        "mechanism": mech,
        "point": "C",
        "targets": [list(v) for v in p["targets"]],
        "motion": "crank-rocker",
        "region": {"O1": [[-box, -box], [box, box]], "A": far, "B": far, "O2": far, "C": far},
        "transmission_deg": 0,  # the papers' formulation: no bound (the default is 20)
    }
    if p["timing"] is not None:
        task["timing"] = p["timing"]
        task["timing_offset"] = True
    if solver:
        task["solver"] = solver
    return task


def run_mjstruct(
    name: str, seed: int, solver: dict[str, int] | None = None
) -> tuple[float, float]:
    from mjstruct.design.api import synthesize

    t0 = time.process_time()
    r = synthesize(task_for(name, solver), seed=seed)
    seconds = time.process_time() - t0
    return float(sum(e * e for e in r.errors)), seconds


# -- one population in one call ----------------------------------------------------------


def batch_ratio(candidates: int = 64, targets: int = 36, repeat: int = 21) -> None:
    """64 candidates x 36 targets in one kinematics call against the numpy floor of one
    candidate x 36 targets, 64 sequential calls (the closed form above)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from mjstruct.design.population import DesignSpace
    from mjstruct.design.task import task_from_dict
    from mjstruct.kinematics.model import KinematicModel
    from timing import race

    task = task_from_dict(task_for("line6"))
    assert task.mechanism is not None
    model = KinematicModel.build(task.mechanism)
    space = DesignSpace.build(model, task.region, ())
    rng = np.random.default_rng(0)
    X = space.x0 + 0.05 * model.scale * rng.standard_normal((candidates, space.size))
    theta = np.linspace(0, 2 * math.pi, targets, endpoint=False)
    xs = [np.array([40, 10, 40, 35, 5, 10, 0.1, 0, 0], float) + rng.random(9) for _ in X]

    def batched() -> Any:
        pop = space.population(X, targets)
        ev = pop.evaluate(pop.cycle(), order=0)
        return pop.where(ev, "C")

    def sequential() -> Any:
        return [closed_form(x, theta) for x in xs]

    tb, ts = race([batched, sequential], repeat, clock=time.process_time)
    ratio = tb / ts
    print(
        f"one call, {candidates} candidates x {targets} targets: {tb * 1e3:.2f} ms; "
        f"closed form, {candidates} sequential calls of {targets} targets: {ts * 1e3:.2f} ms; "
        f"ratio {ratio:.2f}: {verdict(ratio <= BATCH_GOAL)} (goal <= {BATCH_GOAL:g})"
    )


def atlas_task(name: str = "curve18") -> dict[str, Any]:
    """The problem as a task for ``--atlas``: no mechanism of its own, a shorter
    search per candidate."""
    task = task_for(name, {"population": 6, "generations": 60, "restarts": 1})
    for key in ("region", "motion", "mechanism"):
        task.pop(key)
    return task


def atlas_case(name: str = "curve18", links: int = 6, workers: int = 2, seed: int = 0) -> Any:
    """Type and dimensional synthesis: every one-DOF chain of ``links`` links (multiple
    joints included) with each frame, driver and point link, on one problem, ranked
    (returns the atlas result)."""
    from mjstruct.design.atlas import synthesize_atlas

    task = atlas_task(name)
    import resource

    def cpu() -> float:  # this process and its reaped workers
        own = resource.getrusage(resource.RUSAGE_SELF)
        kids = resource.getrusage(resource.RUSAGE_CHILDREN)
        return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

    t0, c0 = time.perf_counter(), cpu()
    r = synthesize_atlas(task, links=links, mj=True, seed=seed, workers=workers)
    wall, spent = time.perf_counter() - t0, cpu() - c0
    ranked = [x for x in r.ranked if x.result is not None]
    print(
        f"atlas, {name}, {links} links: {len(r.ranked)} candidates, {len(ranked)} feasible, "
        f"{wall:.1f} s wall, {spent:.1f} s CPU on {workers} workers"
    )
    for k, x in enumerate(r.ranked[:5], 1):
        c, res = x.candidate, x.result
        f = math.inf if res is None else sum(e * e for e in res.errors)
        print(
            f"  {k}. {c.name} (frame {c.frame}, driver {c.driver}, point on {c.link}): f = {f:.4g}"
        )
    names = sorted({x.candidate.name for x in ranked})
    best = {
        n: min(
            sum(e * e for e in x.result.errors)
            for x in ranked
            if x.candidate.name == n and x.result
        )
        for n in names
    }
    for n in names:
        print(f"  best {n}: f = {best[n]:.4g}")
    return r


def stage_times(name: str, seeds: int) -> None:
    """Where mjstruct's CPU time goes on one problem: the global stage (scipy's
    differential evolution, of which the batched evaluations), the local stage
    (scipy's least squares), the screened first population and the verdicts."""
    import collections

    import scipy.optimize as so

    from mjstruct.design import search
    from mjstruct.design.track import TrackProblem

    spent: collections.Counter[str] = collections.Counter()
    calls: collections.Counter[str] = collections.Counter()

    def timed(owner: Any, attr: str, key: str) -> None:
        inner = getattr(owner, attr)

        def wrapper(*a: Any, **k: Any) -> Any:
            t0 = time.process_time()
            try:
                return inner(*a, **k)
            finally:
                spent[key] += time.process_time() - t0
                calls[key] += 1

        setattr(owner, attr, wrapper)

    timed(so, "differential_evolution", "global stage (DE, all)")
    timed(TrackProblem, "assess", "  batched evaluations (all stages)")
    timed(search, "screened_start", "first population (screen)")
    timed(so, "least_squares", "local stage (least squares)")
    timed(TrackProblem, "finish", "verdicts (kinematics sweep)")
    total = 0.0
    for seed in range(seeds):
        f, t = run_mjstruct(name, seed)
        total += t
        print(f"{name} seed {seed}: f = {f:.4g} in {t:.2f} s CPU")
    print(f"{name}: CPU seconds per run (mean over {seeds} seeds), calls per run")
    for key in spent:
        print(f"  {key:36s} {spent[key] / seeds:6.3f} s  {calls[key] / seeds:7.1f}")
    print(f"  {'whole run':36s} {total / seeds:6.3f} s")


# -- race: CPU time to a target, objective against time ---------------------------------

#: the target per problem: the best value a long plain DE run reaches on the same
#: formulation (curve18: population 30, 4000 generations, 254 s CPU, as measured for
#: issue 33), or an exact fit (line6, timed5)
TARGETS = {"line6": 1e-10, "curve18": 3.61e-3, "ellipse10": 0.699, "timed5": 1e-10}
#: CPU seconds at which the curves are printed
CURVE_AT = (0.5, 1, 2, 5, 10, 20, 50, 100)


def vectorised_objective(X: np.ndarray, targets: np.ndarray, timing: Any) -> np.ndarray:
    """``baseline_objective`` of every column of ``X`` (variables x candidates) at once."""
    X = np.atleast_2d(X)
    r1, r2, r3, r4, rcx, rcy, th0, x0, y0 = X[:9]
    theta2 = np.asarray(timing)[:, None] if timing is not None else X[9:]
    A = r2 * np.exp(1j * theta2)
    e = r1 - A
    f = np.abs(e)
    with np.errstate(invalid="ignore", divide="ignore"):
        alpha = np.arccos((r3 * r3 + f * f - r4 * r4) / (2 * r3 * f))
    C = A + (rcx + 1j * rcy) * np.exp(1j * (np.angle(e) + alpha))
    C = complex(0, 0) + (x0 + 1j * y0) + C * np.exp(1j * th0)
    err = np.sum(np.abs(C - targets[:, None]) ** 2, axis=0)
    err = np.where(np.isfinite(err), err, 1e6)
    L = np.sort(X[:4], axis=0)
    v = np.maximum(0.0, L[0] + L[3] - L[1] - L[2]) + np.maximum(
        0.0, r2 - np.min(X[[0, 2, 3]], axis=0)
    )
    if timing is None:
        steps = np.mod(np.diff(theta2, axis=0), 2 * math.pi).sum(axis=0)
        back = np.mod(-np.diff(theta2, axis=0), 2 * math.pi).sum(axis=0)
        v = v + np.minimum(np.maximum(0, steps - 2 * math.pi), np.maximum(0, back - 2 * math.pi))
    out: np.ndarray = err + PENALTY * v
    return out


def race_baseline(name: str, seed: int, limit: float) -> list[tuple[float, float]]:
    """scipy's DE, vectorised (deferred updating), on the closed form until ``limit``
    CPU seconds: (CPU seconds, best feasible sum of squared errors) per generation."""
    from scipy.optimize import differential_evolution

    p = PROBLEMS[name]
    targets, bounds = baseline_bounds(name)
    t0 = time.process_time()
    curve: list[tuple[float, float]] = []
    best = [math.inf]

    def note(intermediate_result: Any) -> bool:
        f, ok = baseline_score(name, np.asarray(intermediate_result.x))
        if ok:
            best[0] = min(best[0], f)
        spent = time.process_time() - t0
        curve.append((spent, best[0]))
        return spent > limit or best[0] <= TARGETS[name]

    differential_evolution(
        vectorised_objective, bounds, args=(targets, p["timing"]), seed=seed,
        vectorized=True, updating="deferred", maxiter=100_000, tol=0, callback=note,
    )  # fmt: skip
    return curve


def race_mjstruct(name: str, seed: int) -> list[tuple[float, float]]:
    """mjstruct's default search: (CPU seconds, best sum of squared errors so far) after
    each stage, from its history (wall seconds mapped to this process's CPU time)."""
    from mjstruct.design.api import synthesize

    clock: list[tuple[float, float]] = []
    w0, c0 = time.perf_counter(), time.process_time()

    def tick(_done: int, _total: int) -> None:
        clock.append((time.perf_counter() - w0, time.process_time() - c0))

    r = synthesize(task_for(name), seed=seed, progress=tick)
    clock.append((time.perf_counter() - w0, time.process_time() - c0))
    walls, cpus = np.array(clock).T
    n = len(r.errors)  # history holds the RMS error: n * RMS^2 is the sum of squares
    return [(float(np.interp(t, walls, cpus)), n * f * f) for _, t, f in r.history]


def time_to(curve: list[tuple[float, float]], target: float) -> float | None:
    return next((t for t, f in curve if f <= target * (1 + 1e-9)), None)


def race(names: list[str], seeds: int, limit: float) -> None:
    """Both contenders per problem and seed: CPU time to the target (or never, with the
    best reached), and the best objective at the CURVE_AT CPU times."""
    for name in names:
        target = TARGETS[name]
        print(f"{name}: target SSE {target:g}")
        for seed in range(1, seeds + 1):
            for who, curve in (("mjstruct", race_mjstruct(name, seed)),
                               ("vectorised DE", race_baseline(name, seed, limit))):  # fmt: skip
                hit = time_to(curve, target)
                best = min((f for _, f in curve), default=math.inf)
                when = f"{hit:.2f} s CPU" if hit is not None else f"never in {curve[-1][0]:.1f} s"
                points = " ".join(
                    f"{min((f for t, f in curve if t <= at), default=math.inf):.3g}"
                    for at in CURVE_AT
                )
                print(f"  seed {seed} {who:14s} to target: {when:22s} best {best:.4g}  "
                      f"curve at {CURVE_AT} s: {points}", flush=True)  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--problems", default=",".join(PROBLEMS))
    ap.add_argument("--batch-only", action="store_true")
    ap.add_argument("--no-baseline", action="store_true")
    ap.add_argument("--atlas", action="store_true", help="only the six-bar atlas case")
    ap.add_argument("--stages", metavar="PROBLEM", help="only: where mjstruct's time goes")
    ap.add_argument("--race", action="store_true", help="only: CPU time to target, curves")
    ap.add_argument("--limit", type=float, default=300.0, help="--race: DE's CPU seconds")
    args = ap.parse_args()
    if args.race:
        race(args.problems.split(","), args.seeds, args.limit)
        return
    if args.stages:
        stage_times(args.stages, args.seeds)
        return
    batch_ratio()
    if args.batch_only:
        return
    if args.atlas:
        atlas_case()
        return
    import scipy.optimize  # noqa: F401

    import mjstruct.design.api  # noqa: F401  (imports outside the timings)

    rows = []
    for name in args.problems.split(","):
        ours, base = [], []
        for seed in range(args.seeds):
            f, t = run_mjstruct(name, seed)
            ours.append((f, t))
            line = f"{name} seed {seed}: mjstruct {f:.4g} in {t:.1f} s"
            if not args.no_baseline:
                fb, tb, ok = run_baseline(name, seed)
                base.append((fb if ok else math.inf, tb))
                mark = "" if ok else " (infeasible: not a crank-rocker with its angles in order)"
                line += f"; plain DE {fb:.4g}{mark} in {tb:.1f} s"
            print(line, flush=True)
        mo = statistics.median(f for f, _ in ours)
        mt = statistics.median(t for _, t in ours)
        row = [name, mo, mt]
        if base:
            bo = statistics.median(f for f, _ in base)
            bt = statistics.median(t for _, t in base)
            row += [bo, bt]
        rows.append(row)
    print("\nmedians (CPU s; inf: the baseline's answer is infeasible)")
    print(
        "problem     mjstruct f (median)  time    plain DE f (median)  time    time ratio"
        f"  f <= DE's  time <= {TIME_GOAL:g} DE's"
    )
    failed = 0
    for row in rows:
        if len(row) == 5:
            name, mo, mt, bo, bt = row
            good, fast = mo <= bo, mt <= TIME_GOAL * bt
            failed += (not good) + (not fast)
            print(
                f"{name:10s}  {mo:19.4g}  {mt:6.1f}  {bo:19.4g}  {bt:6.1f}  {mt / bt:9.3f}"
                f"  {verdict(good):9s}  {verdict(fast)}"
            )
        else:
            name, mo, mt = row
            print(f"{name:10s}  {mo:19.4g}  {mt:6.1f}")
    if any(len(row) == 5 for row in rows):
        print(f"goals: {'all PASS' if not failed else f'{failed} FAIL'}")


if __name__ == "__main__":
    main()
