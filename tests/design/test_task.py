"""Bad task input: one line naming the field, from the library and from the command
(exit status 2, nothing written); a search that finds nothing: exit 1, nothing written."""

from __future__ import annotations

import json
import math

import pytest

from mjstruct.cli.main import main
from mjstruct.design.task import read_task, task_from_dict
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_to_dict, read_mechanism
from project_paths import EXAMPLES


def _task(**changes):
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json"))
    t = {"task": "path", "mechanism": m, "point": "M",
         "targets": [[0.4, 0.6], [0.3, 0.8], [0.1, 0.9]]}  # fmt: skip
    t.update(changes)
    return {k: v for k, v in t.items() if v is not None}


BAD = [
    ({"task": "pathh"}, r"^task: unknown task kind 'pathh'"),
    ({"task": None}, r"^task: missing"),
    ({"point": "O1"}, r"^point: joint 'O1' is on the frame link"),
    ({"point": "X"}, r"^point: 'X' is not a point or joint"),
    ({"targets": [[0.4, 0.6], [0.3]]}, r"^targets\[1\]: expected \[x, y\] with 2 finite numbers"),
    ({"targets": [[0.4, 0.6], [0.3, "a"]]}, r"^targets\[1\]: expected \[x, y\]"),
    ({"targets": [[0.4, 1e400], [0.3, 0.1]]}, r"^targets\[0\]: expected \[x, y\]"),
    ({"targets": []}, r"^targets: expected a non-empty list"),
    ({"timing": [0.1, 0.2]}, r"^timing: 2 driver values for 3 targets"),
    ({"timing_offset": True}, r"^timing_offset: needs a timing list"),
    ({"region": {"A": [[1, 0], [0, 1]]}}, r"^region\.A: xmin 1 > xmax 0"),
    ({"region": {"A": [[0, 2], [1, 1]]}}, r"^region\.A: ymin 2 > ymax 1"),
    ({"region": {"Z": [[0, 0], [1, 1]]}}, r"^region\.Z: 'Z' is not a joint or point"),
    ({"lengths": [2.0, 1.0]}, r"^lengths: min 2 > max 1"),
    ({"lengths": [0.1, 0.5], "fixed": ["O1", "O2"]}, r"^lengths: the fixed 'O1' and 'O2'"),
    ({"motion": "crank-slider"}, r"^motion: unknown motion type 'crank-slider'"),
    ({"motion": "double-rocker"}, r"^motion: untimed targets are matched along a full turn"),
    ({"transmission_deg": 95}, r"^transmission_deg: 95 is outside \[0, 90\)"),
    ({"fixed": ["O1"], "region": {"O1": [[1, 1], [2, 2]]}}, r"^region\.O1: the fixed position"),
    ({"solver": {"population": 0}}, r"^solver\.population: must be in \[4, 100000\]"),
    ({"colour": "red"}, r"^colour: unknown task key"),
    ({"min_singular": 0.1}, r"^min_singular: unknown task key"),
    ({"name": 3}, r"^name: expected a string, got 3"),
    ({"mechanism": {"joints": [{"id": "a", "links": [0]}]}}, r"^mechanism\.joints\[0\]"),
]


@pytest.mark.parametrize(("change", "message"), BAD)
def test_bad_task_names_the_field(change, message):
    with pytest.raises(MechanismError, match=message):
        task_from_dict(_task(**change))


def test_motion_type_needs_a_four_bar():
    m = mechanism_to_dict(read_mechanism(EXAMPLES / "slider-crank.json"))
    m["points"] = [{"id": "P", "link": "2", "at": [0.5, 0.5]}]
    with pytest.raises(MechanismError, match=r"^motion: a motion type can only be required"):
        task_from_dict(
            {
                "task": "path",
                "mechanism": m,
                "point": "P",
                "targets": [[0, 0]],
                "motion": "crank-rocker",
            }
        )


def test_mechanism_path_is_relative_to_the_task_file(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "m.json").write_text(
        json.dumps(mechanism_to_dict(read_mechanism(EXAMPLES / "four-bar.json")))
    )
    t = _task(mechanism="sub/m.json")
    (tmp_path / "t.toml").write_text(
        'task = "path"\nmechanism = "sub/m.json"\npoint = "M"\n'
        "targets = [[0.4, 0.6], [0.3, 0.8]]\n"
    )
    assert read_task(tmp_path / "t.toml").mechanism.joint("B").at is not None
    (tmp_path / "t.json").write_text(json.dumps(t))
    assert read_task(tmp_path / "t.json").point == "M"
    (tmp_path / "u.json").write_text(json.dumps(_task(mechanism="missing.json")))
    with pytest.raises(MechanismError, match=r"^mechanism: .*missing\.json: no such file"):
        read_task(tmp_path / "u.json")


#: at the command: an unknown task kind, a point not on a moving link, targets that are
#: not finite pairs, a timing of the wrong length, min > max (a box, lengths), and
#: requirements that cannot hold (a transmission angle of 90 or more, a double-rocker
#: meeting untimed targets along a full turn)
COMMAND_BAD = [BAD[i] for i in (0, 2, 4, 6, 8, 10, 13, 16, 17)]


@pytest.mark.parametrize(("change", "message"), COMMAND_BAD)
def test_command_refuses_bad_task(tmp_path, capsys, change, message):
    task = tmp_path / "task.json"
    task.write_text(json.dumps(_task(**change)))
    out = tmp_path / "out.json"
    assert main(["synthesize", str(task), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("mjstruct synthesize: " + message[1:].split("\\")[0].split("'")[0])
    assert not out.exists() and list(tmp_path.iterdir()) == [task]


def test_command_without_feasible_design_exits_1_and_writes_nothing(tmp_path, capsys):
    task = tmp_path / "task.json"
    box = [[0.0, 0.0], [0.05, 0.05]]
    task.write_text(
        json.dumps(
            _task(
                motion="crank-rocker",
                transmission_deg=85.0,
                lengths=[0.3, 0.35],  # the frame pivots' boxes hold them >= 0.85 apart
                region={"O1": box, "O2": [[0.9, 0], [0.95, 0.05]]},
                solver={"screen": 200, "local_starts": 2, "restarts": 1},
            )
        )
    )
    out = tmp_path / "out.json"
    assert main(["synthesize", str(task), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "no feasible design: best constraint violation" in err and err.count("\n") == 1
    assert not out.exists()


def test_command_writes_the_design_and_reports(tmp_path, capsys):
    task = tmp_path / "task.json"
    timing = [1.2, 1.6, 2.0]
    task.write_text(
        json.dumps(
            _task(
                timing=timing,
                fixed=["O1", "O2"],
                name="pick and place",
                solver={
                    "population": 5,
                    "generations": 10,
                    "restarts": 1,
                    "screen": 1000,
                    "local_starts": 4,
                },
            )
        )
    )
    out = tmp_path / "out.toml"
    chart = tmp_path / "history.svg"
    args = ["synthesize", str(task), "-o", str(out), "--seed", "3", "--json"]
    assert main([*args, "--history", str(chart)]) == 0
    d = json.loads(capsys.readouterr().out)
    for key in ("objective", "feasible", "errors", "evaluations", "seconds", "seed"):
        assert key in d
    assert d["seed"] == 3 and d["feasible"] is True and len(d["errors"]) == 3
    m = read_mechanism(out)
    assert m.extra["synthesis"]["point"] == "M" and m.extra["synthesis"]["timing"] == timing
    assert m.name == "pick and place"  # the task's name names the design
    assert chart.read_text().startswith("<?xml")
    assert main(["synthesize", str(task), "-o", str(tmp_path / "b.json"), "--seed", "3"]) == 0
    text = capsys.readouterr().out
    assert "path synthesis: objective" in text and "constraint margins" in text
    assert f"wrote {tmp_path / 'b.json'}" in text


def test_command_runs_the_four_bar_matrix_synthesis(tmp_path, capsys):
    task = tmp_path / "ms.toml"
    task.write_text('task = "fourbar-ms"\nchange_point = "4.2"\nswing_deg = 141.06\n')
    out = tmp_path / "ms4.json"
    assert main(["synthesize", str(task), "-o", str(out), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["task"] == "fourbar-ms" and d["feasible"] is True
    assert abs(d["details"]["swing_deg"] - 141.06) < 1e-6
    assert read_mechanism(out).extra["synthesis"]["task"] == "fourbar-ms"


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["--workers", "0"], "--workers"),
        (["--seed", "-1"], "--seed"),
        (["--mj"], "--mj"),
        (["--history", "h.txt"], "--history"),
        (["--targets-chart", "t.csv"], "--targets-chart"),
    ],
)
def test_command_refuses_bad_options(tmp_path, capsys, args, flag):
    task = tmp_path / "task.json"
    task.write_text(json.dumps(_task()))
    out = tmp_path / "out.json"
    assert main(["synthesize", str(task), "-o", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"mjstruct synthesize: {flag}") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == [task]


def test_command_refuses_an_output_that_is_not_a_mechanism_file(tmp_path, capsys):
    task = tmp_path / "task.json"
    task.write_text(json.dumps(_task()))
    assert main(["synthesize", str(task), "-o", str(tmp_path / "out.png")]) == 2
    assert capsys.readouterr().err.startswith("mjstruct synthesize: -o")
    assert list(tmp_path.iterdir()) == [task]


def test_timed_targets_default_to_fewer_generations() -> None:
    """Timed targets (a timing list, or a function task) default to TIMED_GENERATIONS
    global generations, untimed ones to SOLVER_DEFAULTS'; a given value is kept."""
    from mjstruct.design.task import SOLVER_DEFAULTS, TIMED_GENERATIONS

    assert SOLVER_DEFAULTS["generations"] > TIMED_GENERATIONS
    untimed = task_from_dict(_task())
    timed = task_from_dict(_task(timing=[0.1, 0.2, 0.3]))
    function = task_from_dict(_task(task="function", point=None))
    given = task_from_dict(_task(timing=[0.1, 0.2, 0.3], solver={"generations": 150}))
    assert untimed.solver["generations"] == SOLVER_DEFAULTS["generations"]
    assert timed.solver["generations"] == TIMED_GENERATIONS
    assert function.solver["generations"] == TIMED_GENERATIONS
    assert given.solver["generations"] == 150
    assert timed.solver["population"] == SOLVER_DEFAULTS["population"]


def test_text_report_numbers_targets_from_one_with_q_in_degrees():
    # issue 38.6: the text numbered targets from 0 (the charts from 1) and gave q in
    # radians without a unit, continued so that untimed targets looked unordered
    from mjstruct.cli.synthesize import render

    timing = [5.9, 6.1, 0.2 + 2 * math.pi, 0.6]  # met in this order, through 360°
    d = {"task": "path", "objective": 0.01, "feasible": True, "errors": [0.01] * 4,
         "evaluations": 10, "seconds": 0.1, "seed": 0, "margins": {},
         "details": {"timing": timing}, "timed": False}  # fmt: skip
    lines = render(d, "out.json").splitlines()
    head = next(i for i, line in enumerate(lines) if line.strip().startswith("target"))
    assert "q (deg, 0-360; untimed: met in this order)" in lines[head]
    rows = [line.split() for line in lines[head + 1 : head + 5]]
    assert [r[0] for r in rows] == ["1", "2", "3", "4"]
    assert [float(r[2]) for r in rows] == pytest.approx(
        [math.degrees(t) % 360 for t in timing], abs=1e-4
    )
    d["timed"] = True
    assert "q (deg, 0-360; prescribed)" in render(d, "out.json")


def test_fourbar_ms_text_report_gives_the_design_and_keeps_the_clearance(tmp_path, capsys):
    # issue 38.6: the text printed only the objective; the clearance was not in the file
    task = tmp_path / "ms.json"
    task.write_text(json.dumps({"task": "fourbar-ms", "change_point": "4.2",
                                "swing_deg": 140, "clearance": 0.01,
                                "coupler_point": [0.5, 0.3]}))  # fmt: skip
    out = tmp_path / "ms.json.out.json"
    assert main(["synthesize", str(task), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    for words in ("MS = [0.5 0.961902 1.4619]", "crank-rocker, Grashof",
                  "change point: 1 + P2 = P1 + P3", "swing 140.0000 deg", "time ratio 4.1429",
                  "zone: links 1 and 2 in line", "clearance D = 0.01",
                  "u = 0.5 along A -> B, v = 0.3 to its left, from A",
                  "(lengths in the file's unit)"):  # fmt: skip
        assert words in text, words
    assert read_mechanism(out).extra["synthesis"]["clearance"] == 0.01
    # singular reuses it; --clearance overrides it
    assert main(["singular", str(out)]) == 0
    text = capsys.readouterr().out
    assert "zone:" in text and "clearance D = 0.01 from the file" in text
    assert main(["singular", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["clearance"] == 0.01
    assert main(["singular", str(out), "--clearance", "0.02", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["clearance"] == 0.02


def test_singular_text_gives_output_angles_from_0_to_360(capsys):
    # issue 38.8: the output column was signed (-70.53) while the charts use 0-360°
    assert main(["singular", str(EXAMPLES / "fourbar-ms4.json")]) == 0
    lines = capsys.readouterr().out.splitlines()
    head = next(i for i, line in enumerate(lines) if "output (deg)" in line)
    rows = [line.split() for line in lines[head + 1 :] if line.split()[0].endswith(
        ("_extreme", "_limit", "_point"))]  # fmt: skip
    outputs = [float(r[2]) for r in rows]
    assert outputs and all(0.0 <= v < 360.0 for v in outputs)
    assert any(abs(v - (360.0 - 70.5288)) < 1e-3 for v in outputs)
