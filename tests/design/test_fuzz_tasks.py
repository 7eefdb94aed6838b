"""Fuzzing task files (issue 37): random keys and values, each answered by a design
that the kinematics re-verifies, bad input naming a field, or "no feasible design" —
never an internal error, a leaked warning or a design that breaks a promise."""

from __future__ import annotations

import json
import math
import re
import warnings

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from fourbar_oracle import coupler_point
from mjstruct.design.api import synthesize
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

START = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
KEYS = ["task", "point", "targets", "timing", "timing_offset", "angle_offset", "region",
        "lengths", "fixed", "motion", "full_turn", "transmission_deg", "solver", "name",
        "output", "link", "ms", "frame_length", "swing_deg", "change_point", "colour"]  # fmt: skip
#: a field named at the start of a bad-input message: "targets[3]: ", "solver.tol: "
FIELD = re.compile(r"^[\w.\[\]-]+( |: )")

numbers = st.one_of(
    st.floats(-2.0, 2.0),
    st.sampled_from([0.0, -1.0, 1e-300, 1e300, -1e308, 1e6, 90.0, 180.0]),
    st.integers(-3, 100_000),
)
junk = st.one_of(st.none(), st.booleans(), st.text(max_size=4), numbers)
pairs = st.lists(
    st.tuples(st.floats(-0.5, 1.5), st.floats(-0.5, 1.5)).map(list), min_size=1, max_size=6
)


#: keys whose values of the right shape make a valid path task
CLEAN = ["task", "targets", "timing", "region", "lengths", "motion", "transmission_deg",
         "solver", "full_turn"]  # fmt: skip


@st.composite
def values(draw: st.DrawFn, key: str, clean: bool = False) -> object:
    """A value for ``key``: mostly of the right shape, sometimes anything."""
    if not clean and draw(st.integers(0, 9)) == 0:
        return draw(st.one_of(junk, st.lists(junk, max_size=3)))
    if key == "task":
        if clean:
            return draw(st.sampled_from(["path", "path", "function"]))
        return draw(st.sampled_from(["path", "path", "function", "motion", "fourbar-ms"]))
    if key == "full_turn" and clean:
        return draw(st.booleans())
    if key == "point":
        return draw(st.sampled_from(["M", "A", "B", "O1", "Z"]))
    if key == "targets":
        rows = draw(pairs)
        if clean:
            return rows
        if draw(st.booleans()):
            rows = [[*r, draw(numbers)] for r in rows]
        if draw(st.integers(0, 6)) == 0:
            rows[0][0] = draw(numbers)
        return rows
    if key == "timing":
        if draw(st.booleans()):
            return sorted(draw(st.lists(st.floats(0.0, 7.0), min_size=3, max_size=3)))
        return draw(st.lists(st.one_of(st.floats(0.0, 7.0), numbers), min_size=1, max_size=6))
    if key == "region":
        x0, y0 = draw(st.floats(-2.0, 0.5)), draw(st.floats(-2.0, 0.5))
        box = [[x0, y0], [x0 + draw(st.floats(0.0, 3.0)), y0 + draw(st.floats(0.0, 3.0))]]
        if draw(st.integers(0, 4)) == 0:
            box = [[draw(numbers), draw(numbers)], [draw(numbers), draw(numbers)]]
        return {draw(st.sampled_from(["O1", "A", "B", "M", "Q"])): box}
    if key == "lengths":
        if draw(st.booleans()):
            return sorted([draw(st.floats(0.0, 3.0)), draw(st.floats(0.0, 3.0))])
        return [draw(numbers), draw(numbers)]
    if key == "fixed":
        return draw(st.lists(st.sampled_from(["O1", "A", "B", "O2", "M", "Q"]), max_size=5))
    if key == "motion":
        return draw(st.sampled_from(["crank-rocker", "double-crank", "double-rocker", "x"]))
    if key == "solver":
        small = {"population": st.integers(3, 6), "generations": st.integers(0, 3),
                 "restarts": st.integers(1, 2), "samples": st.integers(4, 24),
                 "tol": numbers, "budget": junk}  # fmt: skip
        chosen = draw(st.lists(st.sampled_from(sorted(small)), max_size=3, unique=True))
        return {k: draw(small[k]) for k in chosen}
    if key == "transmission_deg":
        return draw(st.one_of(st.floats(0.0, 60.0), numbers))
    if key in ("frame_length", "swing_deg"):
        return draw(numbers)
    if key == "change_point":
        return draw(st.sampled_from(["4.1", "4.2", "4.3", "4.4"]))
    if key == "ms":
        return draw(st.sampled_from(["MS1", "MS4", [0.5, 1.0, 1.5], [1.0, 1.0]]))
    return draw(junk)


@st.composite
def tasks(draw: st.DrawFn) -> dict[str, object]:
    clean = draw(st.booleans())  # half the tasks: keys that make sense, values of the right shape
    chosen = draw(st.lists(st.sampled_from(CLEAN if clean else KEYS), max_size=4, unique=True))
    task: dict[str, object] = {"task": "path", "mechanism": START, "point": "M",
                               "targets": [[0.5, 1.1], [0.3, 1.1], [0.1, 0.9]]}  # fmt: skip
    for key in chosen:
        task[key] = draw(values(key, clean))
    timing, targets = task.get("timing"), task["targets"]
    if clean and isinstance(timing, list) and isinstance(targets, list):
        task["timing"] = [*timing, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0][: len(targets)]
    solver = {"population": 4, "generations": 2, "restarts": 1, "samples": 16}
    given_solver = task.get("solver")
    if isinstance(given_solver, dict):  # the task's own choices, within a fast search
        solver.update(given_solver)
    if "solver" not in chosen or isinstance(given_solver, dict):
        task["solver"] = solver
    return task


def _reverify(task: dict[str, object], r) -> None:
    """The design as written, moved by the kinematics itself (and, for the path of M,
    by the four-bar's closed form): the reported errors, the order of untimed targets,
    assembly over the range checked."""
    written = json.loads(json.dumps(mechanism_to_dict(r.mechanism)))
    m = mechanism_from_dict(written)
    model = KinematicModel.build(m)
    timing = np.array(r.details["timing"], float)
    lo, hi = r.details["q_range"]
    sweep = np.linspace(lo, hi, 721)
    motion = model.motion(np.unique(np.concatenate([sweep, timing])), order=0)
    assert motion.valid.all(), "the design does not assemble over its range"
    q = np.unique(np.concatenate([sweep, timing]))
    where = np.searchsorted(q, timing)
    targets = np.array(r.mechanism.extra["synthesis"]["targets"], float)
    kind = r.task
    if kind in ("path", "motion"):
        point = r.mechanism.extra["synthesis"]["point"]
        g = model.geometry
        if point in g.points:
            link, z0 = g.points[point]
            z = motion.point(link, z0)[0][where]
        else:
            z = motion.centre(point)[0][where]
        dist = np.abs(z - (targets[:, 0] + 1j * targets[:, 1]))
        if kind == "path":
            assert np.allclose(dist, r.errors, atol=1e-9 * max(1.0, model.scale)), "errors"
            if point == "M":  # the closed form agrees
                oracle = [abs(coupler_point(written, t) - complex(*p)) for t, p in
                          zip(timing, targets, strict=True)]  # fmt: skip
                assert np.allclose(oracle, r.errors, atol=1e-7)
    if "timing" not in task and kind != "function":  # untimed: in order along one turn
        along = np.mod(timing - timing[0], 2 * math.pi)
        assert np.all(np.diff(along) >= 0), f"out of order: {timing}"
        assert hi - lo >= 2 * math.pi - 1e-9
    assert r.feasible and math.isfinite(r.objective)


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
@given(tasks())
def test_a_random_task_is_a_verified_design_or_a_clear_refusal(task):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            r = synthesize(task, seed=0)
        except MechanismError as exc:
            assert FIELD.match(str(exc)), str(exc)
            event("bad input")
            return
        except NumericalError as exc:
            assert str(exc).startswith(("no feasible design", "fourbar-ms:")), str(exc)
            event("no feasible design")
            return
        finally:
            leaked = [w for w in caught if issubclass(w.category, RuntimeWarning)]
            assert not leaked, [str(w.message) for w in leaked]
    event(f"a {r.task} design")
    if r.task == "fourbar-ms":
        model = KinematicModel.build(r.mechanism)
        assert model.motion(model.sweep(90), order=0).valid.any()
        return
    _reverify(task, r)
