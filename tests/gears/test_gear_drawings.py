"""Gears on drawings: pitch circles moving with their axes, marks turning with the
gears, tooth counts, mesh crosses; an animation; DXF pitch circles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.gear_artists import drawn_gears
from mjstruct.plot.scene import scene_at


def test_each_gear_drawn_once():
    model = KinematicModel.build(read_mechanism(example_path("planetary-simple")))
    got = sorted((g.link, g.joint, g.radius, g.teeth) for g in drawn_gears(model))
    assert got == [("0", "O", 50.0, 100), ("1", "O", 10.0, 20), ("2", "P", 20.0, 40)]


def test_pitch_circles_follow_the_axes_and_marks_turn():
    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.plot.drawing import draw_scene

    model = KinematicModel.build(read_mechanism(example_path("planetary-simple")))
    q = 1.2
    ax = draw_scene(scene_at(model, q=q))
    circles = {p.get_gid(): p for p in ax.patches if str(p.get_gid()).startswith("gear:")}
    assert set(circles) == {"gear:0:O", "gear:1:O", "gear:2:P"}
    # the planet's axis on the carrier, turned by (q - q_ref)/6 from (30, 0)
    turn = (q - model.q_ref[0]) / 6
    assert np.allclose(circles["gear:2:P"].center, (30 * math.cos(turn), 30 * math.sin(turn)))
    # the limits hold the ring (radius 50)
    x0, x1 = ax.get_xlim()
    assert x0 < -50 and x1 > 50
    texts = {t.get_text() for t in ax.texts}
    assert {"z = 20", "z = 40", "z = 100"} <= texts
    import matplotlib.pyplot as plt

    plt.close(ax.figure)


def test_animation_and_dxf(tmp_path):
    gif = tmp_path / "planetary.gif"
    assert (
        main(["animate", str(example_path("planetary-2aa")), "--frames", "6", "-o", str(gif)]) == 0
    )
    assert gif.stat().st_size > 0
    ezdxf = pytest.importorskip("ezdxf")
    dxf = tmp_path / "planetary.dxf"
    assert main(["draw", str(example_path("planetary-simple")), "-o", str(dxf)]) == 0
    circles = [e for e in ezdxf.readfile(dxf).modelspace() if e.dxftype() == "CIRCLE"
               and e.dxf.layer == "pitch-circles"]  # fmt: skip
    assert sorted(round(c.dxf.radius, 9) for c in circles) == [10.0, 20.0, 50.0]
