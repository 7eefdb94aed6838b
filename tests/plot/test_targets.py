"""The ``targets`` layer: a synthesised mechanism's file drawn with its task's targets;
``draw --show paths`` shows them with the traced path of the task's point."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.plot.drawing import artists, draw_scene, scene_at, scene_over_cycle


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def synthesised(task: dict) -> dict:
    """The shipped four-bar with its coupler point M, as a synthesis run would write it:
    the task under the file's ``synthesis`` key."""
    d = mechanism_to_dict(read_mechanism(example_path("four-bar")))
    d["synthesis"] = task
    return d


def path_task(frames: int = 12, every: int = 2) -> tuple[dict, np.ndarray]:
    """Path targets on M's own path (from the kinematics: an independent oracle)."""
    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=frames, checks=False)
    m = r.points["M"]
    targets = [[float(m["x"][k]), float(m["y"][k])] for k in range(0, frames, every)]
    return {"task": "path", "point": "M", "targets": targets}, np.array(targets)


def test_draw_show_paths_shows_the_targets_on_the_traced_path(tmp_path, capsys):
    task, targets = path_task()
    f = tmp_path / "designed.json"
    f.write_text(json.dumps(synthesised(task)))
    assert main(["draw", str(f), "--show", "paths", "-o", str(tmp_path / "d.svg")]) == 0
    assert "wrote" in capsys.readouterr().out
    scene = scene_at(KinematicModel.build(read_mechanism(str(f))), layers=("paths",))
    assert scene.targets is not None and scene.targets.point == "M"
    ax = draw_scene(scene)
    (marks,) = [a for a in artists(ax, "targets") if a.get_gid() == "targets"]
    assert np.allclose(marks.get_xydata(), targets)
    # numbered in their order, and said in the footer
    numbers = [a for a in artists(ax, "targets") if a.get_gid()[8:].isdigit()]
    assert [a.get_text() for a in numbers] == [str(i) for i in range(1, len(targets) + 1)]
    (about,) = artists(ax, "targets:about")
    assert about.get_text().startswith(f"× {len(targets)} path targets of point M")
    # the traced path of M passes through every target (they were taken from it)
    (path,) = artists(ax, "path:M")
    trace = path.get_xydata()
    for t in targets:
        assert np.min(np.hypot(*(trace - t).T)) < 1e-9 * scene.model.scale
    # the limits hold the targets
    x0, x1, y0, y1 = scene.limits
    assert ((targets[:, 0] > x0) & (targets[:, 0] < x1)).all()
    assert ((targets[:, 1] > y0) & (targets[:, 1] < y1)).all()


def test_targets_are_fixed_in_an_animation_and_asked_for_alone(tmp_path):
    task, targets = path_task()
    model = KinematicModel.build(mechanism_from_dict(synthesised(task)))
    scene = scene_over_cycle(model, 6, ("targets",))
    from mjstruct.plot.animation import FrameRenderer

    renderer = FrameRenderer(scene, dpi=30)
    assert not any((a.get_gid() or "").startswith("targets") for a in renderer.changing)
    marks = [a for a in artists(renderer.drawing.ax, "targets") if a.get_gid() == "targets"]
    assert len(marks) == 1 and np.allclose(marks[0].get_xydata(), targets)


def test_motion_targets_are_poses_and_function_targets_only_a_line():
    poses = [[0.5, 1.0, 0.3], [0.9, 1.2, 1.1]]
    model = KinematicModel.build(mechanism_from_dict(synthesised(
        {"task": "motion", "targets": poses})))  # fmt: skip
    ax = draw_scene(scene_at(model, layers=("targets",)))
    (arrows,) = artists(ax, "targets:poses")
    u = arrows.U + 1j * arrows.V
    assert np.allclose(np.angle(u), [p[2] for p in poses])
    assert np.allclose(arrows.get_offsets(), [p[:2] for p in poses])
    model = KinematicModel.build(mechanism_from_dict(synthesised(
        {"task": "function", "targets": [[0.0, 1.0], [1.0, 1.2], [2.0, 1.5]]})))  # fmt: skip
    ax = draw_scene(scene_at(model, layers=("paths",)))
    assert [a.get_gid() for a in artists(ax, "targets")] == ["targets:about"]
    assert "3 function targets" in artists(ax, "targets:about")[0].get_text()


def test_bad_targets_and_a_file_without_them_name_the_field(tmp_path, capsys):
    out = str(tmp_path / "d.svg")
    cases = [
        ({"task": "path", "point": "M", "targets": [[0, 1], [2]]},
         "synthesis.targets: target 2 is not a pair of finite numbers"),
        ({"task": "motion", "targets": [[0, 1, "x"]]},
         "synthesis.targets: target 1 is not a triple of finite numbers"),
        ({"task": "path", "targets": [[0, 1]], "timing": [0.1, 0.2]},
         "synthesis.timing: expected 1 finite numbers, one per target"),
    ]  # fmt: skip
    for task, message in cases:
        f = tmp_path / "bad.json"
        f.write_text(json.dumps(synthesised(task)))
        assert main(["draw", str(f), "--show", "paths", "-o", out]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and message in err
    argv = ["draw", str(example_path("four-bar")), "--show", "targets", "-o", out]
    assert main(argv) == 2
    assert "layer 'targets' needs a synthesised mechanism file" in capsys.readouterr().err
    # an analysed mechanism drawn with paths: no targets, no complaint
    assert main(["draw", str(example_path("four-bar")), "--show", "paths", "-o", out]) == 0


def test_a_target_too_far_out_to_draw_is_refused_naming_it(tmp_path, capsys):
    # issue 37: a target at 1e300 was drawn pressed into the picture's corner
    import json

    from mjstruct.cli.main import main
    from project_paths import EXAMPLES

    m = json.loads((EXAMPLES / "four-bar.json").read_text())
    m["synthesis"] = {"task": "path", "point": "M", "targets": [[0.5, 1.0], [1e300, 1e300]]}
    path = tmp_path / "far.json"
    path.write_text(json.dumps(m))
    out = tmp_path / "far.svg"
    assert main(["draw", str(path), "-o", str(out), "--show", "paths"]) == 2
    err = capsys.readouterr().err
    assert "synthesis.targets: target 2 at [1e+300, 1e+300] lies too far out" in err
    assert not out.exists()
    m["synthesis"]["targets"][1] = [1e3, 1e3]  # far, but a task could have it
    path.write_text(json.dumps(m))
    assert main(["draw", str(path), "-o", str(out), "--show", "paths"]) == 0
