"""The four-bar matrix synthesis (task fourbar-ms): MS1-MS5 by name, requirements solved on
the P2-P3 diagram, the built mechanism checked by the kinematics and singular plug-ins,
and bad task input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.design.fourbar_ms import (
    Requirement,
    fourbar_mechanism,
    solve_requirement,
    synthesize_fourbar_ms,
)
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel

MS4_SWING = 2 * math.acos(1 / 3)  # the seed's "doubled swing, up to 140 deg"


def _swing_triangle(P1: float, P2: float, P3: float) -> float:
    """Output swing through the change point of a change-point crank-rocker, from the
    triangle O1 O2 B alone: the output extremes are where |O1 B| = P1 + P2 (stretched)
    and |O1 B| = |P2 - P1| (folded); at the change point one of them puts B on the
    frame line, and the swing is twice the angle from there to the other extreme."""

    def theta(dist: float) -> float:  # angle at O2 between O2->O1 and O2->B
        return math.acos((1 + P3 * P3 - dist * dist) / (2 * P3))

    stretched, folded = theta(P1 + P2), theta(abs(P2 - P1))
    if abs(folded) < 1e-7:  # the folded extreme is on the frame line (O1 side)
        return 2 * stretched
    return 2 * (math.pi - folded)


def _kinematic_swing(m, turns: int = 2, frames: int = 3600) -> float:
    """The output link's swing measured by the kinematics plug-in: a sweep of the
    driver in each assembly mode (the two circuits meet at the change point), the
    smallest arc of the circle holding every output angle seen."""
    angles = []
    for mode in (1, -1):
        d = mechanism_to_dict(m)
        if mode == -1:  # the other circuit: B mirrored in the line A -> O2
            at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
            A, B, O2 = at["A"], at["B"], at["O2"]
            u = (O2 - A) / abs(O2 - A)
            Bm = A + u * ((B - A) / u).conjugate()
            for j in d["joints"]:
                if j["id"] == "B":
                    j["at"] = [Bm.real, Bm.imag]
        model = KinematicModel.build(mechanism_from_dict(d))
        q = model.q_ref[0] + np.linspace(0.0, 2 * np.pi * turns, frames * turns + 1)
        mo = model.motion(q, order=0)
        angles.append(mo.angle("3")[0][mo.valid])
    a = np.sort(np.mod(np.concatenate(angles), 2 * np.pi))
    gaps = np.diff(np.append(a, a[0] + 2 * np.pi))
    return float(2 * np.pi - gaps.max())


@pytest.fixture(scope="module")
def by_name():
    return {
        n: synthesize_fourbar_ms({"task": "fourbar-ms", "ms": n})
        for n in ("MS1", "MS2", "MS3", "MS4", "MS5")
    }


# ---------------------------------------------------------------- the reference matrices


def test_reference_matrices_build_the_shipped_examples(by_name):
    for name, r in by_name.items():
        shipped = read_mechanism(example_path(f"fourbar-{name.lower()}"))
        assert r.mechanism.name == f"fourbar-{name.lower()}"
        for a, b in zip(shipped.joints, r.mechanism.joints, strict=True):
            assert a.id == b.id and a.links == b.links
            assert abs(complex(*a.at) - complex(*b.at)) < 1e-12
        assert r.details["reference_matrix"] == name
        assert r.task == "fourbar-ms" and r.feasible and r.errors == ()


def test_ms4_doubles_the_swing_to_141_06_deg(by_name):
    d = by_name["MS4"].details
    assert d["MS"] == [0.5, 1.0, 1.5]
    assert d["motion"] == "crank-rocker" and d["grashof"] and d["system4"] == [2]
    assert d["swing"] == pytest.approx(MS4_SWING, abs=1e-12)
    assert d["swing"] == pytest.approx(_swing_triangle(0.5, 1.0, 1.5), abs=1e-12)
    assert round(d["swing_deg"], 2) == 141.06
    # the kinematics sees one circuit per mode, 70.53 deg each; together the doubled swing
    assert _kinematic_swing(by_name["MS4"].mechanism) == pytest.approx(MS4_SWING, abs=2e-6)
    kinds = [p["kind"] for p in d["singular"]["singular"]]
    assert kinds.count("output_extreme") == 2 and kinds.count("change_point") == 1


def test_ms2_dwells_for_half_a_turn_and_swings_60_deg_per_side(by_name):
    d = by_name["MS2"].details
    assert d["system4"] == [1, 2] and d["motion"] == "crank-rocker"
    assert d["swing_deg"] == pytest.approx(120.0, abs=1e-9)
    assert d["time_ratio"] is None  # the folded dead point is the whole dwell
    arcs = d["singular"]["fold_arcs"]
    assert len(arcs) == 2
    for a in arcs:
        assert a["kind"] == "output_extreme" and a["q_to"] - a["q_from"] == pytest.approx(
            math.pi, abs=1e-9
        )


def test_ms3_swings_120_deg_per_side_240_through_with_time_ratio_2(by_name):
    d = by_name["MS3"].details
    assert d["system4"] == [3]
    assert d["swing_deg"] == pytest.approx(240.0, abs=1e-9)
    assert d["swing"] == pytest.approx(_swing_triangle(0.5, 1.5, 1.0), abs=1e-12)
    assert d["time_ratio"] == pytest.approx(2.0, abs=1e-12)
    assert _kinematic_swing(by_name["MS3"].mechanism) == pytest.approx(math.radians(240), abs=2e-6)


def test_ms1_and_ms5_are_double_cranks_with_their_change_points(by_name):
    d1, d5 = by_name["MS1"].details, by_name["MS5"].details
    assert d1["motion"] == d5["motion"] == "double-crank"
    assert d1["system4"] == [1, 3] and d5["system4"] == [1, 2, 3]
    q1 = sorted(p["q"] for p in d1["singular"]["singular"] if p["kind"] == "change_point")
    assert q1 == pytest.approx([math.pi, 2 * math.pi], abs=1e-9)
    assert sum(p["kind"] == "change_point" for p in d5["singular"]["singular"]) == 3


# ---------------------------------------------------------------- requirements


def test_change_point_on_4_2_with_the_ms4_swing_gives_ms4_back():
    r = synthesize_fourbar_ms({"task": "fourbar-ms", "change_point": "4.2", "swing_deg": 141.06})
    p1, p2, p3 = r.details["MS"]
    # closed form on (4.2) at p1: p2 = (1 - p1)(1 - c) / (2 p1 - 1 + c), c = cos(s/2)
    c = math.cos(math.radians(141.06) / 2)
    assert p1 == 0.5
    assert p2 == pytest.approx((1 - p1) * (1 - c) / (2 * p1 - 1 + c), rel=1e-12)
    assert p3 == pytest.approx(1 + p2 - p1, rel=1e-15)
    assert p2 == pytest.approx(1.0, abs=1e-4)  # MS4-like
    assert r.details["solve"]["method"] == "root find"
    assert r.details["solve"]["defaults"] == ["P1 = 0.5"]
    assert r.errors[0] < 1e-9 and r.details["errors_of"] == ["swing_deg"]
    # the built mechanism, through the kinematics plug-in: its swing is the requirement
    assert math.degrees(_kinematic_swing(r.mechanism)) == pytest.approx(141.06, abs=1e-4)


@pytest.mark.parametrize(
    ("line", "swing_deg", "P1"),
    [(1, 200.0, 0.5), (2, 120.0, 0.3), (3, 250.0, 0.7)],
)
def test_swing_requirements_against_the_triangle_closed_form(line, swing_deg, P1):
    s = solve_requirement(Requirement(line=line, swing=math.radians(swing_deg), P1=P1))
    assert s.MS[0] == P1
    assert _swing_triangle(*s.MS) == pytest.approx(math.radians(swing_deg), abs=1e-12)


def test_swing_and_time_ratio_give_ms3_and_ms4():
    ms3 = solve_requirement(Requirement(line=3, swing=math.radians(240), time_ratio=2.0))
    got = ms3.MS
    assert got == pytest.approx((0.5, 1.5, 1.0), abs=1e-9) and ms3.free == ("P1", "P2")
    a = math.acos(1 / 3)
    ms4 = solve_requirement(Requirement(line=2, swing=2 * a, time_ratio=(2 * math.pi - a) / a))
    got = ms4.MS
    assert got == pytest.approx((0.5, 1.0, 1.5), abs=1e-9)


def test_dwell_requirement_puts_b_on_o1_and_solves_p1_in_closed_form():
    r = synthesize_fourbar_ms({"change_point": "4.1", "dwell": True, "swing_deg": 150.0})
    p1, p2, p3 = r.details["MS"]
    assert p1 == pytest.approx(math.sin(math.radians(150.0) / 4), rel=1e-12)
    assert p2 == p1 and p3 == pytest.approx(1.0, abs=1e-15)
    arcs = r.details["singular"]["fold_arcs"]
    assert arcs and all(a["q_to"] - a["q_from"] == pytest.approx(math.pi) for a in arcs)
    # without a swing, the diagram's p1 = 0.5: MS2 exactly
    assert synthesize_fourbar_ms({"change_point": "4.2", "dwell": True}).details["MS"] == [
        0.5,
        0.5,
        1.0,
    ]


def test_double_rocker_and_double_crank_requirements():
    r = synthesize_fourbar_ms({"change_point": "4.1", "motion": "double-rocker", "swing_deg": 60})
    assert r.details["motion"] == "double-rocker" and 1 in r.details["system4"]
    assert r.details["swing_deg"] == pytest.approx(60.0, abs=1e-9)
    r = synthesize_fourbar_ms({"change_point": "4.1", "motion": "double-crank", "P2": 1.0})
    assert r.details["MS"] == [0.5, 1.0, 0.5] and r.details["reference_matrix"] == "MS1"


def test_scale_assembly_reference_coupler_point_and_clearance():
    task = {
        "ms": "MS4",
        "name": "folding crank-rocker",
        "description": "MS4 at a fifth of the size",
        "frame_length": 0.2,
        "assembly": -1,
        "reference_deg": 100.0,
        "coupler_point": [0.05, 0.02],
        "clearance": 0.002,
    }
    r = synthesize_fourbar_ms(task, seed=7)
    m = r.mechanism
    assert m.name == "folding crank-rocker"
    assert mechanism_to_dict(m)["description"] == "MS4 at a fifth of the size"
    at = {j.id: complex(*j.at) for j in m.joints}
    assert abs(at["O2"] - at["O1"]) == pytest.approx(0.2)
    assert abs(at["A"] - at["O1"]) == pytest.approx(0.1)
    assert abs(at["B"] - at["A"]) == pytest.approx(0.2)
    assert abs(at["O2"] - at["B"]) == pytest.approx(0.3)
    assert math.degrees(math.atan2(at["A"].imag, at["A"].real)) == pytest.approx(100.0)
    # assembly -1: B on the right of A -> O2
    assert ((at["O2"] - at["A"]).conjugate() * (at["B"] - at["A"])).imag < 0
    (p,) = m.points
    u = (at["B"] - at["A"]) / abs(at["B"] - at["A"])
    assert p.link == "2" and complex(*p.at) == pytest.approx(at["A"] + (0.05 + 0.02j) * u)
    assert r.details["MS"] == pytest.approx([0.5, 1.0, 1.5], rel=1e-12) and r.seed == 7
    # zones from the singular plug-in: formula (3) at the output extremes (input and
    # coupler stretched: l = 0.2, r = 0.1 -> lambda 0.5, delta D / l = 0.01)
    for pos in r.details["singular"]["singular"]:
        assert pos["zone"]
        if pos["kind"] == "output_extreme":
            (z,) = pos["zone"]
            arg = 1 - 0.01 * (2 * 0.5 + 0.01) / (2 * 1.5)
            assert z["psi"] == pytest.approx(2 * math.acos(arg), abs=1e-12)
    # deterministic: the same task gives the same file and numbers (timings aside)
    again = synthesize_fourbar_ms(task, seed=7)
    assert mechanism_to_dict(again.mechanism) == mechanism_to_dict(m)
    assert again.details == r.details


# ---------------------------------------------------------------- bad task input


@pytest.mark.parametrize(
    ("task", "field"),
    [
        ({"ms": "MS7"}, "ms"),
        ({"ms": [0.5, 1.0]}, "ms"),
        ({"ms": [0.5, -1.0, 1.0]}, "ms[1]"),
        ({"ms": [0.1, 0.1, 3.0]}, "ms"),
        ({"ms": "MS4", "swing_deg": 100}, "swing_deg"),
        ({"ms": "MS4", "motion": "double-crank"}, "motion"),
        ({"ms": "MS4", "colour": "red"}, "colour"),
        ({"task": "path", "ms": "MS4"}, "task"),
        ({"swing_deg": 100}, "change_point"),
        ({"change_point": "4.4", "swing_deg": 100}, "change_point"),
        ({"change_point": "4.2"}, "swing_deg"),
        ({"change_point": "4.2", "swing_deg": 400}, "swing_deg"),
        ({"change_point": "4.2", "swing_deg": 200}, "swing_deg"),
        ({"change_point": "4.2", "swing_deg": 150, "time_ratio": 10}, "time_ratio"),
        ({"change_point": "4.2", "swing_deg": 141, "time_ratio": 2, "P1": 0.5}, "time_ratio"),
        ({"change_point": "4.3", "dwell": True}, "dwell"),
        ({"change_point": "4.2", "dwell": "yes"}, "dwell"),
        ({"change_point": "4.2", "time_ratio": 0.5}, "time_ratio"),
        ({"change_point": "4.2", "motion": "double-crank", "swing_deg": 90}, "motion"),
        ({"ms": "MS4", "assembly": 0}, "assembly"),
        ({"ms": "MS4", "clearance": -1}, "clearance"),
        ({"ms": "MS4", "frame_length": 0}, "frame_length"),
        ({"ms": "MS4", "reference_deg": 0}, "reference_deg"),
        ({"ms": "MS4", "coupler_point": [1]}, "coupler_point"),
        ({"ms": "MS4", "description": 3}, "description"),
    ],
)
def test_bad_task_input_is_one_line_naming_the_field(task, field):
    with pytest.raises(MechanismError) as e:
        synthesize_fourbar_ms(task)
    msg = str(e.value)
    assert msg.startswith(f"{field}: ") and "\n" not in msg


def test_a_swing_beyond_the_line_says_what_is_reachable():
    with pytest.raises(MechanismError, match=r"about 120 deg to 180 deg"):
        synthesize_fourbar_ms({"change_point": "4.2", "swing_deg": 200})


def test_mechanism_helper_matches_requirement_lengths():
    m = fourbar_mechanism((0.5, 1.0, 1.5), frame_length=2.0)
    at = {j.id: complex(*j.at) for j in m.joints}
    assert abs(at["B"] - at["O2"]) == pytest.approx(3.0)
    assert m.drivers == ("O1",) and m.frame == "0"


# ---------------------------------------------------------------- the command line


def test_cli_synthesize_fourbar_ms_writes_the_mechanism(tmp_path, capsys):
    import json

    from mjstruct.cli.main import main

    task = tmp_path / "ms.json"
    task.write_text(
        json.dumps(
            {"task": "fourbar-ms", "change_point": "4.2", "swing_deg": 141.06, "clearance": 0.01}
        )
    )
    out = tmp_path / "designed.json"
    assert main(["synthesize", str(task), "-o", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["task"] == "fourbar-ms" and d["feasible"] and d["max_error"] < 1e-9
    assert d["details"]["MS"] == pytest.approx([0.5, 1.0000903914, 1.5000903914], rel=1e-9)
    assert all(p["zone"] for p in d["details"]["singular"]["singular"])
    # the written file is the designed mechanism: the singular command reads it back
    assert main(["singular", str(out), "--json"]) == 0
    back = json.loads(capsys.readouterr().out)
    assert back["fourbar"]["swing"] == pytest.approx(math.radians(141.06), abs=1e-12)
    assert back["fourbar"]["system4"] == [2]


def test_cli_requirement_no_four_bar_meets_is_exit_2_and_nothing_written(tmp_path, capsys):
    import json

    from mjstruct.cli.main import main

    task = tmp_path / "ms.json"
    task.write_text(json.dumps({"task": "fourbar-ms", "change_point": "4.2", "swing_deg": 200}))
    out = tmp_path / "designed.json"
    assert main(["synthesize", str(task), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "swing_deg: no crank-rocker on (4.2)" in err
    assert not out.exists()
