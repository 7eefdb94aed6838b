"""The notebook explorer: its picture follows the driver and the joints it moves.

The oracle for positions is a kinematic model built afresh from the edited mechanism
file (planned anew, followed from its reference to the driver value), not the
explorer's own model, which keeps the first plan; the singular positions are those of
:func:`singular_analysis` on that edited file.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mjstruct.io import mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.drawing import artists
from mjstruct.plot.explorer_view import ExplorerView
from mjstruct.singular.analysis import singular_analysis
from project_paths import EXAMPLES

SIX_BAR = EXAMPLES / "six-bar-mj-slider.json"


def edited(path, **moves):
    """The mechanism file with joints moved: id -> (x, y)."""
    d = mechanism_to_dict(read_mechanism(path))
    for j in d["joints"]:
        if j["id"] in moves:
            j["at"] = list(moves[j["id"]])
    return mechanism_from_dict(d)


def followed(m, q):
    """Joint centres of ``m`` at driver value ``q``, followed from the reference."""
    model = KinematicModel.build(m)
    path = np.linspace(model.q_ref[0], q, 60)
    motion = model.motion(path, order=0)
    assert motion.valid.all()
    return {j.id: complex(motion.centre(j.id)[0][-1]) for j in m.joints}


def pin(view, joint):
    (circle,) = [a for a in artists(view.ax, f"joint:{joint}") if hasattr(a, "center")]
    return complex(*circle.center)


@pytest.fixture(scope="module")
def view():
    return ExplorerView(read_mechanism(SIX_BAR), ["B", "O2"], frames=180)


def test_the_driver_slider_puts_the_pins_where_the_kinematics_does(view):
    before = view.png()
    view.set_driver(123.0)
    after = view.png()
    q = float(view.q[0])
    assert abs(np.degrees(q) % 360 - 124.0) < 1e-9  # the nearest frame: 2° steps
    oracle = followed(view.original, q)
    for joint in ("A", "B", "C"):
        assert abs(pin(view, joint) - oracle[joint]) < 1e-9 * view.model.scale
    (marker,) = artists(view.strip, "range:q")
    assert marker.get_xdata()[0] == pytest.approx(124.0)
    assert before != after


def test_a_joint_slider_rebuilds_the_mechanism_paths_and_singular_positions(view):
    (path,) = artists(view.ax, "path:P")
    old = np.array(path.get_xydata())
    assert view.move_joint("O2", 3.3, 0.4)
    new = np.array(path.get_xydata())
    assert old.shape != new.shape or np.abs(old - new).max() > 1e-3  # the line changed
    m = edited(SIX_BAR, O2=(3.3, 0.4))
    # the traced path of P: the fresh model's over the same frames
    model = KinematicModel.build(m)
    motion = model.motion(model.sweep(180), order=0)
    link, at = model.geometry.points["P"]
    z = np.asarray(motion.point(link, at)[0])
    assert np.abs(new[:180, 0] + 1j * new[:180, 1] - z).max() < 1e-9
    # the pins at the frame shown (the driver's value is kept), once drawn
    view.png()
    q = float(view.q[0])
    oracle = followed(m, q)
    assert abs(pin(view, "O2") - (3.3 + 0.4j)) < 1e-12
    assert abs(pin(view, "B") - oracle["B"]) < 1e-9
    # the strip marks the singular positions of the edited file
    expected = sorted(np.degrees(p.q) % 360 for p in singular_analysis(m).singular)
    marked = sorted(x for a in artists(view.strip, "singular") for x in a.get_xdata())
    assert np.allclose(marked, expected, atol=1e-9)
    assert view.problem is None
    assert "assembles over the whole turn of O1" in view.summary()


def test_moving_a_joint_moves_the_slider_block_drawn_at_it():
    view = ExplorerView(read_mechanism(EXAMPLES / "six-bar-mj-slider.json"), ["C"], frames=36)
    assert view.moves_with["C"] == ["C", "S"]
    assert view.move_joint("C", 5.3, 2.0)
    assert view.centre("S") == view.centre("C") == 5.3 + 2.0j


def test_a_geometry_that_cannot_be_drawn_is_said_and_the_last_picture_kept():
    view = ExplorerView(read_mechanism(SIX_BAR), ["B"], frames=36)
    picture = view.png()
    assert not view.move_joint("B", 0.0, 1.0)  # onto A: link 2 has no length
    assert view.problem is not None and "'A' and 'B'" in view.problem
    assert view.summary()[0] == view.problem
    assert view.png() == picture
    assert view.centre("B") == 2.615 + 2.47j  # the last geometry drawn
    assert view.move_joint("B", 2.6, 2.5)  # and back to one that can be
    assert view.problem is None


def test_a_crank_that_does_not_turn_fully_shows_its_range_and_input_limits():
    view = ExplorerView(read_mechanism(SIX_BAR), ["O2"], frames=72)
    assert view.move_joint("O2", 3.0, 1.5)
    r = singular_analysis(edited(SIX_BAR, O2=(3.0, 1.5)))
    assert not r.input_range.full_turn
    limits = sorted(np.degrees(p.q) % 360 for p in r.singular if p.kind == "input_limit")
    (marks,) = artists(view.strip, "singular:input_limit")
    assert np.allclose(sorted(marks.get_xdata()), limits)
    # the green stretches end at the input limits; a frame between them does not assemble
    ends = sorted(x for a, b in view.assembly_intervals() for x in (a, b) if 0 < x < 360)
    assert np.allclose(ends, limits)
    view.set_driver(0.5 * (limits[0] + limits[1]))
    assert not view.assembles
    view.png()
    assert artists(view.ax, "note")[0].get_text().endswith("does not assemble")
    assert any(line.endswith("the mechanism does not assemble") for line in view.summary())


def test_a_joint_leaving_the_drawing_gets_a_larger_one():
    view = ExplorerView(read_mechanism(SIX_BAR), ["O2"], frames=36)
    x0 = view.ax.get_xlim()[0]
    assert view.move_joint("O2", 3.0, -2.5)
    y0 = view.ax.get_ylim()[0]
    assert y0 < -2.5 and view.ax.get_xlim()[0] <= x0
    view.set_driver(30.0)
    view.png()
    oracle = followed(edited(SIX_BAR, O2=(3.0, -2.5)), float(view.q[0]))
    assert abs(pin(view, "B") - oracle["B"]) < 1e-9


def test_bad_arguments_name_the_field():
    from mjstruct.errors import MechanismError

    m = read_mechanism(SIX_BAR)
    with pytest.raises(MechanismError, match="joints: 'Z'"):
        ExplorerView(m, ["Z"])
    with pytest.raises(MechanismError, match="frames"):
        ExplorerView(m, frames=2)
    view = ExplorerView(m, ["B"], frames=12)
    with pytest.raises(MechanismError, match="joint: 'A'"):
        view.move_joint("A", 0.0, 0.0)


KERNEL_CELL = """
import json, warnings
import numpy as np
import mjstruct
from mjstruct.plot.drawing import artists

warnings.simplefilter("error")  # a warning in the widget's callbacks fails the test
m = mjstruct.read_mechanism(PATH)
ex = mjstruct.explore(m, joints=["B", "O2"], frames=120)
display(ex)
out = {}
pins = lambda: {j: list(a.center) for j in ("A", "B") for a in artists(ex.view.ax, "joint:" + j)
                if hasattr(a, "center")}
picture = ex.image.value
ex.driver.value = 150.0
out["q"] = float(ex.view.q[0])
out["pins"] = pins()
out["picture_changed"] = ex.image.value != picture
path = np.array(artists(ex.view.ax, "path:P")[0].get_xydata()).tolist()
ex.sliders["O2"][0].value = 3.3
ex.sliders["O2"][1].value = 0.4
out["path_before"] = path
out["path_after"] = np.array(artists(ex.view.ax, "path:P")[0].get_xydata()).tolist()
out["pins_after"] = pins()
ex.sliders["B"][0].value = 0.0
ex.sliders["B"][1].value = 1.0          # onto A: cannot be drawn
out["message"] = ex.message.value
print("RESULT" + json.dumps(out))
"""


def test_the_explorer_in_a_kernel_redraws_when_its_sliders_move(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipywidgets")
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(f"PATH = {str(SIX_BAR)!r}\n" + KERNEL_CELL)]
    client = nbclient.NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = nb.cells[0].outputs
    errors = [o for o in outputs if o.get("output_type") == "error"]
    stderr = "".join(o.get("text", "") for o in outputs if o.get("name") == "stderr")
    assert not errors and "Traceback" not in stderr, (errors, stderr)
    assert any("application/vnd.jupyter.widget-view+json" in o.get("data", {}) for o in outputs)
    text = "".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    out = json.loads(text.split("RESULT", 1)[1])
    # the driver: the pins where the kinematics puts them at that value
    assert abs(np.degrees(out["q"]) % 360 - 150.0) < 1e-9
    oracle = followed(read_mechanism(SIX_BAR), out["q"])
    for joint in ("A", "B"):
        assert abs(complex(*out["pins"][joint]) - oracle[joint]) < 1e-9
    assert out["picture_changed"]
    # a joint: the path changed, the pins follow the edited mechanism
    assert out["path_before"] != out["path_after"]
    oracle = followed(edited(SIX_BAR, O2=(3.3, 0.4)), out["q"])
    assert abs(complex(*out["pins_after"]["B"]) - oracle["B"]) < 1e-9
    # a geometry that cannot be drawn: a message, no traceback
    assert "this geometry cannot be drawn" in out["message"]
    assert "Traceback" not in text


def test_a_prismatic_driver_slides_over_its_stroke():
    d = mechanism_to_dict(read_mechanism(EXAMPLES / "slider-crank.json"))
    d["drivers"] = ["O4"]  # the piston's slide drives the crank
    view = ExplorerView(mechanism_from_dict(d), frames=60, stroke=0.3)
    assert view.unit == "length" and view.driver_range() == (0.0, 0.3, 0.005)
    view.set_driver(0.05)
    assert view.q[0] == pytest.approx(0.05) and view.assembles
    # the slide's limits: the block where crank and rod are in line, |B(s) - O1| = l2 ± l1
    # (stretched out, folded): the slides s where that holds
    c = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    (u,) = [complex(*j["axis"]) for j in d["joints"] if j["id"] == "O4"]
    u /= abs(u)
    l1, l2 = abs(c["A"] - c["O1"]), abs(c["B"] - c["A"])
    w = c["B"] - c["O1"]  # |w + s u|^2 = r^2: s^2 + 2 Re(w conj u) s + |w|^2 - r^2 = 0
    b = (w * u.conjugate()).real
    roots = [-b + sign * np.sqrt(b * b - abs(w) ** 2 + r**2) for r in (l2 + l1, l2 - l1)
             for sign in (-1, 1)]  # fmt: skip
    limits = sorted(p.q for p in view.singular_positions() if p.kind == "input_limit")
    assert len(limits) == 2 and all(min(abs(x - np.array(roots))) < 1e-9 for x in limits)
    assert limits[1] == pytest.approx(roots[1], abs=1e-9)  # stretched out, ahead
    view.set_driver(0.5 * (limits[1] + 0.3))  # beyond the crank's reach
    assert not view.assembles
    (marks,) = artists(view.strip, "singular:input_limit")
    assert sorted(marks.get_xdata()) == sorted(limits)


def test_summary_says_two_positions_at_one_driver_value_are_two_branches():
    # issue 38.7: "output extreme at 38.6°, output extreme at 38.6°" read as a repeat;
    # the first try's singular curve passes the crank's 38.6° on two assembly branches
    m = read_mechanism(EXAMPLES / "six-bar-mj-slider-first-try.json")
    at = [p for p in singular_analysis(m).singular if p.kind == "output_extreme"]
    same = [p for p in at if abs(math.degrees(p.q) % 360 - 38.6) < 0.05]
    assert len(same) == 2  # the oracle: two positions there
    words = ExplorerView(m, [], frames=36).summary()[1]
    assert "output extreme at 38.6° on 2 assembly branches" in words
    assert words.count("at 38.6°") == 1
