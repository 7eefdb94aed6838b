"""Motion synthesis: a link through prescribed poses (a point's position and the link's
angle).

Owns :func:`motion_problem`: the motion task as a :class:`~mjstruct.design.track.
TrackProblem` fitting both the position of the task's ``point`` and the angle of its
link; an angle error counts as that angle times the starting mechanism's size, so
one error per pose, sqrt(|Δp|² + (size·Δθ)²), mixes both.  Where it applies — a
hinged four-bar whose task link is the coupler — the exact start is Burmester's
(:mod:`mjstruct.design.burmester`): for four or five poses (beyond five, five
spread ones) the dyads that guide the coupler exactly are paired into four-bars,
screened in one batched call, and the best join the global search's first
population; least squares over all poses follows.

Examples
--------
>>> from mjstruct.design.task import task_from_dict
>>> from mjstruct.io import mechanism_to_dict, read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> m = mechanism_to_dict(read_mechanism(example_path("four-bar")))
>>> t = task_from_dict({"task": "motion", "mechanism": m, "point": "M",
...                     "targets": [[0.4, 0.6, 0.5], [0.2, 0.9, 0.7]], "timing": [1, 2]})
>>> p = motion_problem(t)
>>> p.link, p.targets, round(p.weight, 3)
('2', 2, 1.073)
"""

from __future__ import annotations

import numpy as np

from mjstruct.design.burmester import burmester_dyads
from mjstruct.design.constraints import MIN_SINE
from mjstruct.design.population import DesignSpace
from mjstruct.design.task import Task, is_fourbar
from mjstruct.design.track import TrackProblem
from mjstruct.kinematics.model import KinematicModel
from mjstruct.typing import FloatArray

#: four-bars from Burmester's dyads kept as starts
BURMESTER_STARTS = 6


def _coupler_joints(task: Task) -> tuple[str, str, str, str] | None:
    """(O1, A, B, O2) when the task's link is the coupler of a hinged four-bar driven
    at a frame joint."""
    m = task.mechanism
    if m is None or not is_fourbar(m) or task.link is None:
        return None
    driver = m.joint(m.drivers[0])
    if m.frame not in driver.links or m.frame in {
        x for j in m.link_joints[task.link] for x in m.joint(j).links
    }:
        return None
    other = next(j for j in m.joints if m.frame in j.links and j.id != driver.id)
    crank = next(x for x in driver.links if x != m.frame)
    rocker = next(x for x in other.links if x != m.frame)
    A = next(j for j in m.joints if crank in j.links and j.id != driver.id)
    B = next(j for j in m.joints if rocker in j.links and j.id != other.id)
    return driver.id, A.id, B.id, other.id


def burmester_starts(problem: TrackProblem) -> list[FloatArray]:
    """Four-bars whose coupler passes exactly through four or five of the poses, as
    global variable vectors, the best (feasible first, by energy) first."""
    task = problem.task
    joints = _coupler_joints(task)
    if joints is None or problem.positions is None or problem.angles is None:
        return []
    T = problem.targets
    if T < 4:
        return []
    idx = list(range(T)) if T <= 5 else sorted({round(k) for k in np.linspace(0, T - 1, 5)})
    poses = [(complex(problem.positions[i]), float(problem.angles[i])) for i in idx]
    size = problem.scale
    dyads = burmester_dyads(poses, size=size)
    if len(dyads) < 2:
        return []
    O1n, An, Bn, O2n = joints
    space = problem.space
    start = problem.start()
    k = space.size
    P0, R0 = poses[0][0], np.exp(1j * poses[0][1])
    rows = []
    for i, (C1, m1) in enumerate(dyads):
        for j, (C2, m2) in enumerate(dyads):
            if i == j or abs(C1 - C2) < 1e-9 * size:
                continue
            pos = dict(space.start)
            pos[O1n], pos[An] = C1, P0 + R0 * m1
            pos[O2n], pos[Bn] = C2, P0 + R0 * m2
            if task.point is not None:
                pos[task.point] = P0
            x = [v for n in space.names for v in (pos[n].real, pos[n].imag)]
            rows.append(np.concatenate([x, start[k:]]))
    if not rows:
        return []
    X = np.clip(np.array(rows), *problem.bounds())
    a = problem.assess(X)
    problem.evaluations += len(X)
    worst = np.min(np.stack(list(a.margins.values())), axis=0)
    key = np.where(worst >= -MIN_SINE, a.energy, np.inf)
    order = np.lexsort((-worst, key))[:BURMESTER_STARTS]
    return [X[i] for i in order]


def motion_problem(task: Task) -> TrackProblem:
    """The motion task ``task`` ready for :func:`~mjstruct.design.search.solve`."""
    assert task.kind == "motion" and task.mechanism is not None and task.point is not None
    model = KinematicModel.build(task.mechanism)
    positions = task.targets[:, 0] + 1j * task.targets[:, 1]
    space = DesignSpace.build(
        model, task.region, task.fixed, margin=1.0, around=list(positions), points=[task.point]
    )
    problem = TrackProblem(
        task,
        task.point,
        positions,
        task.link,
        task.targets[:, 2].copy(),
        model.scale,
        task.timing,
        space=space,
    )
    problem.extra_starts = burmester_starts(problem)
    return problem
