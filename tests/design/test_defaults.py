"""Defaults and honest reports: the default transmission bound, a design variable on
its box's bound named, ``change_point: true`` of the four-bar matrix synthesis."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point
from mjstruct.cli.main import main
from mjstruct.design.api import synthesize
from mjstruct.design.fourbar_ms import synthesize_fourbar_ms
from mjstruct.design.task import DEFAULT_TRANSMISSION_DEG, task_from_dict
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

FAST = {"restarts": 1, "screen": 1500, "local_starts": 4}


def _task(**extra):
    m = read_mechanism(EXAMPLES / "four-bar.json")
    q = KinematicModel.build(m).q_ref[0] + np.linspace(0, 2 * math.pi, 8, endpoint=False)
    d = mechanism_to_dict(m)
    targets = [[z.real, z.imag] for z in (coupler_point(d, float(v)) for v in q)]
    return {"task": "path", "mechanism": d, "point": "M", "targets": targets,
            "solver": FAST, **extra}  # fmt: skip


def _min_transmission(d, frames=720):
    """The smallest angle between coupler A->B and rocker O2->B over a turn (oracle)."""
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    q0 = math.atan2((at["A"] - at["O1"]).imag, (at["A"] - at["O1"]).real)
    least = 90.0
    for q in q0 + np.linspace(0, 2 * math.pi, frames, endpoint=False):
        A, B = coupler_point(d, float(q), "A"), coupler_point(d, float(q), "B")
        u, v = B - A, B - at["O2"]
        s = abs((u.conjugate() * v).imag) / (abs(u) * abs(v))
        least = min(least, math.degrees(math.asin(min(1.0, s))))
    return least


def test_every_task_has_the_default_transmission_bound_and_zero_switches_it_off():
    assert task_from_dict(_task()).transmission_deg == DEFAULT_TRANSMISSION_DEG == 20.0
    assert task_from_dict(_task(transmission_deg=0)).transmission_deg == 0.0
    r = synthesize(_task(), seed=1)
    d = mechanism_to_dict(r.mechanism)
    assert r.feasible and _min_transmission(d) >= DEFAULT_TRANSMISSION_DEG - 0.05
    assert r.details["min_transmission_deg"] >= DEFAULT_TRANSMISSION_DEG - 1e-9


def test_a_variable_on_its_box_bound_is_named(tmp_path, capsys):
    # the targets of the example's path, its crank pivot kept 0.2 to the right of where
    # the answer has it and O2 fixed (without it a cognate fits exactly inside the box):
    # the search presses O1 against the box's left side
    task = _task(region={"O1": [[0.2, -0.5], [0.6, 0.5]]}, transmission_deg=0, fixed=["O2"])
    r = synthesize(task, seed=0)
    assert "O1.x (lower)" in r.details["on_bound"]
    assert not any(name.startswith(("A.", "B.", "M.")) for name in r.details["on_bound"])
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    assert main(["synthesize", str(path), "-o", str(tmp_path / "o.json")]) == 0
    assert "on a bound of its box" in capsys.readouterr().out


def test_change_point_true_takes_the_line_that_meets_the_requirements():
    # MS4's swing on 4.2 (the test of the named line gives MS4 back): any line may serve
    # a swing; the answer meets it and names the lines that could
    r = synthesize_fourbar_ms({"task": "fourbar-ms", "change_point": True, "swing_deg": 141.06})
    assert r.objective < 1e-6 and r.details["requirement"]["change_point"] in ("4.1", "4.2", "4.3")
    assert set(r.details["lines_tried"]) <= {"4.1", "4.2", "4.3"}
    assert abs(r.details["swing_deg"] - 141.06) < 1e-6
    with pytest.raises(MechanismError, match=r"^change_point: no line of system \(4\) meets"):
        synthesize_fourbar_ms(
            {"task": "fourbar-ms", "change_point": True, "swing_deg": 359, "time_ratio": 5}
        )
