"""Pictures a careful draughtsman would sign: labels clear of pins and bars, legends
off the drawing and off the curves, titles inside the figure, angles in degrees for
people, GIFs filled by the mechanism, SVG element ids unique."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import xml.etree.ElementTree as ET
from collections import Counter

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.patches import Circle
from PIL import Image

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.animation import FrameRenderer, write_animation
from mjstruct.plot.charts import draw_chart
from mjstruct.plot.drawing import artists, draw_scene, scene_at, scene_over_cycle, write_drawing


def model_of(name: str) -> KinematicModel:
    return KinematicModel.build(read_mechanism(example_path(name)))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def svg_ids(path) -> list[str]:
    return [e.get("id") for e in ET.parse(path).iter() if e.get("id") is not None]


@pytest.mark.parametrize(
    ("name", "layers", "speed"),
    [
        ("kin-radial-engine-5", ("assur", "velocity", "acceleration", "paths"), 1.0),
        ("slider-crank-seed000-dynamics", ("inertia", "velocity", "acceleration"), 10.0),
    ],
)
def test_svg_element_ids_are_unique(tmp_path, name, layers, speed):
    out = tmp_path / "d.svg"
    write_drawing(scene_at(model_of(name), 1.0, layers, speed=speed), str(out))
    ids = svg_ids(out)
    repeated = {k: n for k, n in Counter(ids).items() if n > 1}
    assert not repeated and len(ids) > 30
    # what the drawing shows is named in the file
    assert {"joint:A", "velocity", "title", "title:q", "scalebar"} & set(ids)


def test_chart_and_zone_svgs_have_unique_ids(tmp_path):
    from mjstruct.plot.ms_diagram import plot_singular_zones
    from mjstruct.singular.analysis import singular_analysis

    m = read_mechanism(example_path("fourbar-ms4"))
    figures = [
        plot_singular_zones(m, singular_analysis(m, clearance=0.02)),
        draw_chart(model_of("four-bar"), "transmission", frames=72),
    ]
    for k, fig in enumerate(figures):
        out = tmp_path / f"{k}.svg"
        fig.savefig(out)
        ids = svg_ids(out)
        assert len(ids) == len(set(ids)) > 10


def _display_boxes(ax, gid):
    fig = ax.figure
    r = fig.canvas.get_renderer()
    return [(a, a.get_window_extent(r)) for a in artists(ax, gid)]


def _segment_hits_box(p, q, box, shrink=1.0) -> bool:
    """Whether the segment p-q (display points) crosses the box shrunk by ``shrink`` px."""
    x0, y0, x1, y1 = box.x0 + shrink, box.y0 + shrink, box.x1 - shrink, box.y1 - shrink
    t = np.linspace(0.0, 1.0, 200)
    x = p[0] + t * (q[0] - p[0])
    y = p[1] + t * (q[1] - p[1])
    return bool(((x > x0) & (x < x1) & (y > y0) & (y < y1)).any())


@pytest.mark.parametrize(
    ("name", "q", "layers"),
    [
        ("kin-radial-engine-5", 1.2, ("assur", "velocity")),
        ("slider-crank", 1.0, ("velocity", "acceleration")),
        ("four-bar", None, ()),
        ("scotch-yoke", 0.8, ("velocity",)),
    ],
)
def test_joint_labels_sit_clear_of_pins_and_bars(name, q, layers):
    ax = draw_scene(scene_at(model_of(name), q, layers))
    fig = ax.figure
    fig.canvas.draw()
    to_px = ax.transData.transform
    pins = [a for a in artists(ax, "joint") if isinstance(a, Circle)]
    bars = [a for a in artists(ax, "link") if hasattr(a, "get_xydata")]
    labels = _display_boxes(ax, "label:joint")
    assert labels
    for label, box in labels:
        for pin in pins:
            c = to_px(pin.center)
            r = to_px((pin.center[0] + pin.radius, pin.center[1]))[0] - c[0]
            # the nearest point of the box to the pin's centre is outside the pin
            nx = min(max(c[0], box.x0), box.x1)
            ny = min(max(c[1], box.y0), box.y1)
            assert np.hypot(nx - c[0], ny - c[1]) >= r - 1.0, (label.get_text(), pin.get_gid())
        for bar in bars:
            (p, qq) = to_px(bar.get_xydata())[[0, -1]]
            assert not _segment_hits_box(p, qq, box), (label.get_text(), bar.get_gid())


def test_assur_legend_sits_below_the_mechanism_not_on_it():
    ax = draw_scene(scene_at(model_of("zhivago"), layers=("assur", "paths")))
    fig = ax.figure
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    legend = ax.get_legend()
    assert legend is not None and legend.get_gid() == "legend:assur"
    box = legend.get_window_extent(r)
    drawn = [a.get_window_extent(r) for g in ("link", "joint", "path", "ground", "label")
             for a in artists(ax, g)]  # fmt: skip
    assert box.y1 < min(b.y0 for b in drawn)
    scale = [a.get_window_extent(r) for a in artists(ax, "scalebar")]
    assert box.y1 < min(b.y0 for b in scale)  # under the scale bar and the keys


def test_titles_give_q_in_degrees_and_radians_on_request():
    scene = scene_at(model_of("slider-crank"), 1.0)
    ax = draw_scene(scene)
    (q,) = artists(ax, "title:q")
    assert q.get_text() == "q = 57.3°"
    ax = draw_scene(scene, ax=plt.figure().add_subplot(), radians=True)
    (q,) = artists(ax, "title:q")
    assert q.get_text() == "q = 1 rad"


def test_a_long_name_is_broken_into_lines_inside_the_figure(tmp_path):
    from mjstruct.io import mechanism_from_dict, mechanism_to_dict

    d = mechanism_to_dict(read_mechanism(example_path("four-bar")))
    d["name"] = "a four-bar with a very long name " * 5
    scene = scene_at(KinematicModel.build(mechanism_from_dict(d)))
    ax = draw_scene(scene)
    fig = ax.figure
    fig.canvas.draw()
    (title,) = [a for a in artists(ax, "title") if a.get_gid() == "title"]
    box = title.get_window_extent(fig.canvas.get_renderer())
    assert title.get_text().count("\n") >= 1
    assert box.x0 >= 0 and box.x1 <= fig.bbox.x1 and box.y1 <= fig.bbox.y1


@pytest.mark.parametrize("what", ["angles", "paths", "reactions", "transmission", "jacobian"])
def test_chart_titles_fit_and_legends_leave_the_curves_alone(what):
    name = "slider-crank-seed000-dynamics" if what == "reactions" else "four-bar"
    fig = draw_chart(model_of(name), what, frames=72, speed=10.0)
    fig.tight_layout()
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    title = fig._suptitle.get_window_extent(r)
    assert title.x0 >= 0 and title.x1 <= fig.bbox.x1 and title.y1 <= fig.bbox.y1
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is not None:
            assert not legend.get_window_extent(r).overlaps(ax.get_window_extent(r))
            assert legend.get_window_extent(r).x1 <= fig.bbox.x1 + 1


def test_gif_frames_are_big_and_filled_by_the_drawing(tmp_path):
    out = tmp_path / "engine.gif"
    write_animation(scene_over_cycle(model_of("kin-radial-engine-5"), 4), str(out))
    with Image.open(out) as gif:
        width, height = gif.size
        rgb = np.asarray(gif.convert("RGB"))
    assert width >= 480 and height >= 400  # 6 inches at the default 80 dpi
    ink = np.flatnonzero((rgb < 250).any(axis=2).any(axis=0))
    rows = np.flatnonzero((rgb < 250).any(axis=2).any(axis=1))
    # the drawing, title and footer reach close to every edge: no wide white margins
    assert (ink[-1] - ink[0]) / width > 0.85
    assert (rows[-1] - rows[0]) / height > 0.9


def test_animation_labels_keep_their_side_between_nearby_frames():
    scene = scene_over_cycle(model_of("kin-radial-engine-5"), 72)
    renderer = FrameRenderer(scene, dpi=40)
    sides = []
    for k in range(12):
        renderer.drawing.show(k)
        (label,) = artists(renderer.drawing.ax, "label:joint:A")
        sides.append(np.angle(complex(*label.xyann)))
    # the label at the multiple joint changes side rarely, not every frame
    flips = np.sum(np.abs(np.angle(np.exp(1j * np.diff(sides)))) > 0.5)
    assert flips <= 2


def _pins_in_pixels(model: KinematicModel) -> np.ndarray:
    """Each pin's centre and its radius along x and along y, in pixels."""
    ax = draw_scene(scene_at(model))
    ax.figure.canvas.draw()
    to_px = ax.transData.transform
    rows = []
    for pin in sorted(
        (a for a in artists(ax, "joint") if isinstance(a, Circle)), key=Circle.get_gid
    ):
        (x, y), r = pin.center, pin.radius
        c = to_px((x, y))
        rows.append([*c, to_px((x + r, y))[0] - c[0], to_px((x, y + r))[1] - c[1]])
    return np.array(rows)


@pytest.mark.parametrize("size", [1e-45, 1e-20, 1e20, 1e45])
def test_a_drawing_looks_the_same_at_any_size(tmp_path, size):
    # matplotlib's own equal aspect fails below spans of about 1e-35: a four-bar of
    # size 1e-45 came out squashed, its pins ellipses
    import json

    data = json.loads(example_path("four-bar").read_text())
    for item in [*data["joints"], *data.get("points", [])]:
        item["at"] = [size * x for x in item["at"]]
    path = tmp_path / "scaled.json"
    path.write_text(json.dumps(data))
    plain = _pins_in_pixels(model_of("four-bar"))
    scaled = _pins_in_pixels(KinematicModel.build(read_mechanism(path)))
    assert plain.shape == scaled.shape and len(plain) >= 4
    assert np.allclose(scaled[:, 2], scaled[:, 3])  # round pins
    assert np.allclose(plain, scaled, atol=0.5), (plain, scaled)  # the same picture
