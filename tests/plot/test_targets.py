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


def test_function_chart_puts_the_targets_where_the_design_meets_them():
    # issue 38.1: the chart drew the targets without the angle offset the search found,
    # and in radians; targets from the kinematics (an independent oracle) shifted by a
    # known offset must sit on the output curve, in degrees as every chart against q
    from mjstruct.plot.design_charts import draw_targets

    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=12, checks=False)
    q = r.q[2:8, 0]
    angle = r.links["3"]["angle"][2:8]
    offset = -1.2
    task = {"task": "function", "link": "3", "timed": True, "angle_offset": offset,
            "targets": [[float(a), float(b - offset)] for a, b in zip(q, angle, strict=True)],
            "timing": [float(a) for a in q]}  # fmt: skip
    fig = draw_targets(mechanism_from_dict(synthesised(task)))
    ax = fig.axes[0]
    (curve,) = artists(ax, "output")
    (marks,) = artists(ax, "targets")
    x, y = curve.get_xydata().T
    ok = np.isfinite(y)
    tx, ty = marks.get_xydata().T
    assert np.allclose(tx, np.degrees(q) % 360.0)
    assert np.allclose(ty, np.interp(tx, x[ok], y[ok]), atol=0.05)  # degrees
    assert np.allclose((ty - np.degrees(angle) + 180.0) % 360.0, 180.0)
    assert "(°)" in ax.get_xlabel() and "(°)" in ax.get_ylabel()
    assert "offset -68.75°" in marks.get_label()


def test_footer_says_untimed_targets_are_untimed():
    # issue 38.4: a synthesised file keeps the driver values as met for untimed targets
    # too; the footer said "(timed)" for them
    task, _ = path_task()
    for timed, words in ((False, "(untimed: in their order over a cycle)"), (True, "(timed)")):
        entry = {**task, "timing": [0.1 * k for k in range(len(task["targets"]))],
                 "timed": timed}  # fmt: skip
        model = KinematicModel.build(mechanism_from_dict(synthesised(entry)))
        (about,) = artists(draw_scene(scene_at(model, layers=("paths",))), "targets:about")
        assert about.get_text().endswith(words)
        assert ("(timed)" in about.get_text()) == timed


def test_a_link_that_carries_a_point_is_the_plate_through_it_in_every_frame():
    # issue 38.5: the four-bar's coupler point M was a dot floating beside bar A-B
    from matplotlib.path import Path

    from mjstruct.plot.animation import FrameRenderer

    m = read_mechanism(example_path("four-bar"))
    r = kinematic_analysis(m, frames=6, checks=False)  # the oracle: another entry point
    scene = scene_over_cycle(KinematicModel.build(m), 6, ())
    renderer = FrameRenderer(scene, dpi=30)
    for k in (0, 3):
        renderer.drawing.show(k)
        (plate,) = artists(renderer.drawing.ax, "link:2")
        outline = Path(plate.get_xy())
        corners = [complex(r.joints[j]["x"][k], r.joints[j]["y"][k]) for j in ("A", "B")]
        corners.append(complex(r.points["M"]["x"][k], r.points["M"]["y"][k]))
        # each of A, B and M is a corner of the plate (the hull of three points)
        xy = plate.get_xy()
        for z in corners:
            assert np.min(np.hypot(xy[:, 0] - z.real, xy[:, 1] - z.imag)) < 1e-9
        inside = sum(corners) / 3
        assert outline.contains_point((inside.real, inside.imag))


def test_labels_keep_off_the_target_crosses():
    # issue 38.5: a label over a target cross hid it; crosses put where the labels of
    # the plain drawing are must push those labels elsewhere
    def labels_at(data: dict) -> tuple[list, np.ndarray]:
        plt.close("all")
        scene = scene_at(KinematicModel.build(mechanism_from_dict(data)), 1.0, ("paths",))
        ax = draw_scene(scene)
        fig = ax.get_figure()
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        found = [a for a in artists(ax, "label") if a.get_gid().startswith("label:")]
        boxes = [a.get_window_extent(renderer) for a in found]
        return list(zip(found, boxes, strict=True)), ax.transData

    plain = mechanism_to_dict(read_mechanism(example_path("four-bar")))
    before, to_data = labels_at(plain)
    names = ("label:joint:A", "label:joint:B", "label:point:M", "label:link:2")
    spots = [b for a, b in before if a.get_gid() in names]
    assert len(spots) == 4
    centres = np.array([[(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2] for b in spots])
    targets = to_data.inverted().transform(centres)
    task = {"task": "path", "point": "M", "targets": targets.tolist()}
    after, to_data = labels_at(synthesised(task))
    crosses = to_data.transform(targets)
    for label, box in after:
        for x, y in crosses:
            assert not box.contains(x, y), label.get_gid()


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
