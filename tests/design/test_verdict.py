"""The final verdict (issue 37): every promise of the contract re-checked from the
design's own geometry — order of untimed targets, the range, the timing, the
transmission bound, lengths, region, fixed, the four-bar motion and the errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fourbar_oracle import coupler_point
from mjstruct.design.api import synthesize
from mjstruct.design.task import task_from_dict
from mjstruct.design.track import with_synthesis
from mjstruct.design.verify import check_motion, final_verdict, ordered_along_turn
from mjstruct.errors import NumericalError
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from project_paths import EXAMPLES

TINY = {"population": 4, "generations": 5, "restarts": 1, "samples": 16}


def _four_bar() -> dict:
    return mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))


def _in_order(timing: list[float]) -> bool:
    along = np.mod(np.asarray(timing) - timing[0], 2 * math.pi)
    return bool(np.all(np.diff(along) >= 0))


@pytest.mark.parametrize(
    ("targets", "seed"),
    [  # issue 37 A1: these came back feasible with their targets met out of order
        ([[0.877, 0.278], [-0.23, 0.943], [0.551, 0.12], [0.472, 1.279], [1.368, 0.216]], 1),
        ([[0.643, 0.144], [0.689, 0.176], [0.283, 1.281], [-0.046, 0.746], [-0.332, 1.165]], 0),
        ([[1.015, 0.495], [0.559, 1.072], [0.329, 0.969], [0.922, 1.364], [-0.27, 0.958]], 2),
    ],
)
def test_untimed_targets_out_of_order_are_never_called_feasible(targets, seed):
    task = {"task": "path", "mechanism": _four_bar(), "point": "M", "targets": targets,
            "solver": TINY}  # fmt: skip
    try:
        r = synthesize(task, seed=seed)
    except NumericalError as exc:
        assert str(exc).startswith("no feasible design")
        return
    assert r.feasible and _in_order(r.details["timing"])


def test_order_along_one_turn_starting_anywhere():
    assert ordered_along_turn(np.array([6.0, 0.5, 1.0]))[1] == ""  # across the cut
    assert ordered_along_turn(np.array([1.84, 1.64, 3.66, 1.51, 1.86]))[1].startswith(
        "targets met out of order"
    )
    # a tie of rounding (the duplicate targets) is one driver value
    q, why = ordered_along_turn(np.array([1.5206227008042252, 1.5206227008042235, 2.0]))
    assert why == "" and q[0] == q[1]


def test_the_verdict_refuses_an_out_of_order_timing_of_a_good_design():
    start = _four_bar()
    m = read_mechanism(EXAMPLES / "four-bar.json")
    q = [1.84, 1.64, 3.66, 1.51, 1.86]
    targets = [[z.real, z.imag] for z in (coupler_point(start, v) for v in q)]
    task = task_from_dict({"task": "path", "mechanism": start, "point": "M", "targets": targets})
    design = with_synthesis(m, task, q)
    broken = final_verdict(task, design, q)
    assert broken and broken[0].startswith("targets met out of order")
    ordered = sorted(q)
    task2 = task_from_dict({"task": "path", "mechanism": start, "point": "M",
                            "targets": [targets[q.index(v)] for v in ordered]})  # fmt: skip
    assert final_verdict(task2, design, ordered, errors=[0.0] * 5) == []


def test_the_verdict_rechecks_every_requirement_from_the_geometry():
    start = _four_bar()
    m = read_mechanism(EXAMPLES / "four-bar.json")
    q = [1.0, 1.5, 2.0]
    targets = [[z.real, z.imag] for z in (coupler_point(start, v) for v in q)]
    base = {"task": "path", "mechanism": start, "point": "M", "targets": targets, "timing": q}
    assert final_verdict(task_from_dict(base), m, q, errors=[0.0] * 3) == []
    cases = {
        "lengths": {"lengths": [0.0, 0.5]},
        "region.B": {"region": {"B": [[-1, -1], [0.5, 0.5]]}},
        "motion": {"motion": "double-crank", "timing": None},
        "transmission_deg": {"transmission_deg": 89.0},
    }
    for field, extra in cases.items():
        data = {**base, **extra}
        data = {k: v for k, v in data.items() if v is not None}
        task = task_from_dict(data)
        # the start may itself break the task (that is the point): judge the file's four-bar
        broken = final_verdict(task, m, q, errors=[0.0] * 3)
        assert any(b.startswith(field) for b in broken), (field, broken)
    # errors that are not the design's own
    broken = final_verdict(task_from_dict(base), m, q, errors=[0.0, 0.1, 0.0])
    assert broken == ["errors: the reported errors are not the design's own"]
    # a timing other than the task's
    broken = final_verdict(task_from_dict(base), m, [1.0, 1.5, 2.1], errors=None)
    assert broken == ["timing: the targets are not met at the driver values the task gives"]


def test_a_range_that_no_double_resolves_is_not_checked_as_if_it_were():
    m = read_mechanism(EXAMPLES / "four-bar.json")
    c = check_motion(m, np.array([1e300, 5e300]), full_turn=False)
    assert not c.ok and "driver range" in c.reason
    model = KinematicModel.build(m)
    c = check_motion(m, model.q_ref + np.array([0.1, 0.2]), full_turn=False)
    assert c.ok


def test_duplicate_untimed_targets_come_back_at_one_driver_value():
    # issue 37 "Also": the second of two equal targets came back 1.7e-15 rad earlier
    targets = [[0.5, 1.1], [0.3, 1.1], [0.3, 1.1], [0.1, 0.9], [0.05, 0.6]]
    task = {"task": "path", "mechanism": _four_bar(), "point": "M", "targets": targets,
            "solver": {**TINY, "generations": 10}}  # fmt: skip
    r = synthesize(task, seed=1)
    timing = r.details["timing"]
    assert timing[1] == timing[2] and r.errors[1] == r.errors[2]
    assert _in_order(timing)


def test_the_fourbar_ms_verdict_rechecks_the_written_geometry():
    from mjstruct.design.fourbar_ms import synthesize_fourbar_ms
    from mjstruct.design.verify import fourbar_ms_verdict
    from mjstruct.io import mechanism_from_dict

    r = synthesize_fourbar_ms({"task": "fourbar-ms", "change_point": "4.2", "swing_deg": 141.0576})
    d = r.details
    swing = math.radians(141.0576)
    assert fourbar_ms_verdict(r.mechanism, d["motion"], d["system4"], 2, swing) == []
    moved = mechanism_to_dict(r.mechanism)
    moved["joints"][2]["at"] = [v * 1.01 for v in moved["joints"][2]["at"]]  # B off its place
    broken = fourbar_ms_verdict(mechanism_from_dict(moved), d["motion"], d["system4"], 2, swing)
    assert broken and broken[0].startswith(("change_point", "swing_deg", "motion"))
