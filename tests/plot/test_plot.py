"""Drawings: what is drawn (pins, polygons, MJ marks, blocks, vectors) against the model,
and that a scene asks the kinematics only for the order its layers need."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.patches import Circle, Polygon

from mjstruct.catalog_files import example_path
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.plot.drawing import (
    artists,
    draw_scene,
    guide_sides,
    scene_at,
    scene_over_cycle,
)
from mjstruct.plot.layers import kinematic_order, parse_layers


def model_of(name: str, drivers=None) -> KinematicModel:
    return KinematicModel.build(read_mechanism(example_path(name)), drivers)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def one(ax, gid):
    found = artists(ax, gid)
    assert len(found) == 1, (gid, found)
    return found[0]


def polygon_centre(poly: Polygon) -> complex:
    xy = poly.get_xy()[:4]
    return complex(xy[:, 0].mean(), xy[:, 1].mean())


@pytest.mark.parametrize("name", ["slider-crank", "kin-radial-engine-5", "zhivago", "scotch-yoke"])
def test_drawn_centres_are_the_kinematics_positions(name):
    m = read_mechanism(example_path(name))
    r = kinematic_analysis(m, frames=8, checks=False)
    model = r.model
    k = 3
    ax = draw_scene(scene_at(model, q=r.q[k]))
    tol = 1e-9 * model.scale
    for j in m.joints:
        want = complex(r.joints[j.id]["x"][k], r.joints[j.id]["y"][k])
        pin = one(ax, f"joint:{j.id}")  # one pin (or block) artist per joint
        if j.kind == "R":
            assert isinstance(pin, Circle)
            assert abs(complex(*pin.center) - want) <= tol
        else:
            assert isinstance(pin, Polygon)
            if guide_sides(model, j.id)[1] == j.links[1]:  # the block carries the centre
                assert abs(polygon_centre(pin) - want) <= 1e-6 * model.scale


def test_mj_marks_and_polygons():
    m = read_mechanism(example_path("kin-radial-engine-5"))
    ax = draw_scene(scene_at(KinematicModel.build(m)))
    for j in m.joints:
        marks = artists(ax, f"mj:{j.id}")
        if j.is_multiple:  # one dot per link on the pin's ring
            assert len(marks) == 1 and len(marks[0].get_offsets()) == len(j.links)
        else:
            assert marks == []
    # the sliders are blocks on hatched frame guides, the crank pin is the driver
    assert len([a for a in artists(ax, "joint") if isinstance(a, Polygon)]) == 5
    assert len(artists(ax, "guide")) == 5
    assert artists(ax, "driver:O")
    assert len(artists(ax, "ground")) == 2  # triangle and hatching of the one frame pivot


def test_polygon_count_follows_the_links():
    m = read_mechanism(example_path("zhivago"))
    model = KinematicModel.build(m)
    ax = draw_scene(scene_at(model))
    expected = 0
    for link in m.links:
        if link == m.frame:
            continue
        z = np.array(
            sorted(
                {model.geometry.centres[j] for j in m.link_joints[link]},
                key=lambda c: (c.real, c.imag),
            )
        )
        if len(z) >= 3:
            d = z - z.mean()
            if np.abs(np.imag(np.conj(d[:, None]) * d[None, :])).max() > 1e-6 * model.scale**2:
                expected += 1
    polys = [a for a in artists(ax, "link") if isinstance(a, Polygon)]
    assert expected >= 1
    assert len(polys) == expected


def test_vectors_only_when_asked_and_equal_to_sigma_times_speed():
    m = read_mechanism(example_path("slider-crank"))
    model = KinematicModel.build(m)
    plain = draw_scene(scene_at(model))
    assert artists(plain, "velocity") == [] and artists(plain, "acceleration") == []
    r = kinematic_analysis(m, frames=8, speed=2.5, checks=False)
    k = 2
    scene = scene_at(model, q=r.q[k], layers=("velocity",), speed=2.5)
    ax = draw_scene(scene)
    assert artists(ax, "acceleration") == []
    quiver = one(ax, "velocity")
    sites = {
        complex(x, y): complex(u, v)
        for (x, y), u, v in zip(quiver.get_offsets(), quiver.U, quiver.V, strict=True)
    }
    for jid in ("A", "B"):
        z = complex(r.joints[jid]["x"][k], r.joints[jid]["y"][k])
        v = complex(r.joints[jid]["vx"][k], r.joints[jid]["vy"][k])
        got = next(w for p, w in sites.items() if abs(p - z) < 1e-9)
        assert abs(got - v) <= 1e-9 * max(1.0, abs(v))
    ax2 = draw_scene(scene_at(model, q=r.q[k], layers=("acceleration",), speed=2.5))
    assert artists(ax2, "velocity") == [] and len(artists(ax2, "acceleration")) == 1


@pytest.fixture
def orders(monkeypatch):
    asked: list[int] = []
    original = KinematicModel.motion

    def recording(self, q, order=2, *args, **kwargs):
        asked.append(order)
        return original(self, q, order, *args, **kwargs)

    monkeypatch.setattr(KinematicModel, "motion", recording)
    return asked


@pytest.mark.parametrize(
    ("layers", "expected"),
    [
        ((), [0]),
        (("assur",), [0]),
        (("velocity",), [1]),
        (("acceleration",), [2]),
        (("velocity", "acceleration"), [2]),
        (("paths",), [0, 0]),
    ],
)
def test_a_drawing_computes_only_what_it_shows(orders, layers, expected):
    draw_scene(scene_at(model_of("slider-crank"), q=1.0, layers=layers))
    assert orders == expected


@pytest.mark.parametrize(("layers", "expected"), [((), [0]), (("velocity", "paths"), [1])])
def test_an_animation_scene_computes_only_what_it_shows(orders, layers, expected):
    scene = scene_over_cycle(model_of("four-bar"), 6, layers)
    assert orders == expected
    assert scene.motion.order == expected[0]


def test_layers_parse_and_orders():
    assert parse_layers("velocity, assur,velocity") == ("velocity", "assur")
    assert kinematic_order(("paths", "assur")) == 0
    with pytest.raises(MechanismError, match="show: unknown layer 'speed'"):
        parse_layers("speed")
    assert kinematic_order(("inertia",)) == 2 and kinematic_order(("reactions",)) == 0


def test_force_layers_say_when_the_dynamics_plug_in_is_missing(monkeypatch):
    from mjstruct.plot import layers

    monkeypatch.setattr(layers, "dynamics_available", lambda: False)
    with pytest.raises(MechanismError, match="needs the dynamics plug-in"):
        parse_layers("velocity,reactions")


def test_assur_layer_colours_groups():
    model = model_of("kin-radial-engine-5")
    ax = draw_scene(scene_at(model, layers=("assur",)))
    scene = scene_at(model, layers=("assur",))
    d = scene.decomposition
    assert d is not None and len(d.groups) == 5
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert sum(t.startswith("group") for t in texts) == len(d.groups)
    from matplotlib.colors import to_rgb

    bar = {a.get_gid(): to_rgb(a.get_color()) for a in artists(ax, "link")}
    # each group (connecting rod, piston) in its own colour: the rod's bar and the
    # piston's block share it, and the groups differ
    rods = [g.links[0] for g in d.groups]
    assert len({bar[f"link:{x}"] for x in rods}) == len(rods)
    for g in d.groups:
        slider = next(
            j
            for j in scene.model.geometry.axes
            if g.links[1] in scene.model.mechanism.joint(j).links
        )
        block = one(ax, f"joint:{slider}")
        assert to_rgb(block.get_facecolor()) == bar[f"link:{g.links[0]}"]


def scaled(name: str, factor: float) -> KinematicModel:
    from mjstruct.io import mechanism_to_dict

    d = mechanism_to_dict(read_mechanism(example_path(name)))
    for j in d["joints"]:
        j["at"] = [factor * x for x in j["at"]]
    for p in d.get("points", []):
        p["at"] = [factor * x for x in p["at"]]
    return KinematicModel.build(mechanism_from_dict(d))


def test_drawing_is_the_same_at_any_scale():
    ref = scene_at(scaled("slider-crank", 1.0), q=1.0, layers=("velocity", "paths"))
    for factor in (1e-3, 100.0):
        s = scene_at(scaled("slider-crank", factor), q=1.0, layers=("velocity", "paths"))
        assert np.allclose(np.array(s.limits) / factor, ref.limits, rtol=1e-9, atol=1e-12)
        assert s.pin == pytest.approx(ref.pin * factor)
        ax = draw_scene(s)
        circle = one(ax, "joint:A")
        assert circle.radius == pytest.approx(s.pin)


def test_animation_limits_cover_every_frame():
    scene = scene_over_cycle(model_of("kin-radial-engine-5"), 12, ("velocity",))
    x0, x1, y0, y1 = scene.limits
    for j in scene.model.mechanism.joints:
        z = scene.motion.centre(j.id)[0]
        assert (z.real > x0).all() and (z.real < x1).all()
        assert (z.imag > y0).all() and (z.imag < y1).all()


def gappy_four_bar() -> KinematicModel:
    # the coupler is the shortest link (a Grashof double rocker) driven as a crank
    return KinematicModel.build(
        mechanism_from_dict(
            {
                "frame": "0",
                "drivers": ["O1"],
                "joints": [
                    {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
                    {"id": "A", "links": ["1", "2"], "at": [0, 2]},
                    {"id": "B", "links": ["2", "3"], "at": [1.0, 2.0]},
                    {"id": "O2", "links": ["3", "0"], "at": [2.6, 0]},
                ],
            }
        )
    )


def test_frames_that_do_not_assemble_are_gaps_with_a_note():
    scene = scene_over_cycle(gappy_four_bar(), 24)
    bad = np.flatnonzero(~scene.motion.valid)
    good = np.flatnonzero(scene.motion.valid)
    assert bad.size and good.size
    ax = draw_scene(scene, int(bad[0]))
    assert "does not assemble" in one(ax, "note").get_text()
    assert artists(ax, "joint") == [] and artists(ax, "ground")  # the frame stays
    ax2 = draw_scene(scene, int(good[0]), ax=plt.figure().add_subplot())
    assert artists(ax2, "note") == [] and len(artists(ax2, "joint")) == 4


def test_branch_points_are_marked():
    parallelogram = mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
                {"id": "A", "links": ["1", "2"], "at": [0, 1]},
                {"id": "B", "links": ["2", "3"], "at": [2, 1]},
                {"id": "O2", "links": ["3", "0"], "at": [2, 0]},
            ],
        }
    )
    scene = scene_over_cycle(KinematicModel.build(parallelogram), 36)
    assert scene.motion.events
    e = scene.motion.events[0]
    ax = draw_scene(scene, e.frame)
    marks = artists(ax, "branch")
    assert any(e.kind in getattr(a, "get_text", lambda: "")() for a in marks)
    quiet = next(k for k in range(36) if all(ev.frame != k for ev in scene.motion.events))
    assert artists(draw_scene(scene, quiet, ax=plt.figure().add_subplot()), "branch") == []


def test_bad_arguments_name_the_parameter():
    model = model_of("slider-crank")
    with pytest.raises(MechanismError, match=r"^q: "):
        scene_at(model, q=[1.0, 2.0])
    with pytest.raises(MechanismError, match=r"^paths: 'Z'"):
        scene_at(model, layers=("paths",), paths=["Z"])
    with pytest.raises(MechanismError, match=r"^speed: "):
        scene_at(model, speed=0.0)


def test_force_layers_draw_the_dynamics_result(orders):
    from mjstruct.dynamics import dynamic_analysis

    m = read_mechanism(example_path("slider-crank-seed000-dynamics"))
    model = KinematicModel.build(m)
    r = dynamic_analysis(m, speed=10.0, frames=8, outputs=("reactions",))
    k = 3
    orders.clear()
    scene = scene_at(model, q=r.q[k], layers=("reactions",), speed=10.0)
    assert orders[0] == 0  # our own motion: positions only
    ax = draw_scene(scene)
    quiver = one(ax, "reactions")
    assert len(quiver.U) == len(m.joints)  # one arrow per simple joint
    for j in m.joints:
        z = complex(*one(ax, f"joint:{j.id}").center) if j.kind == "R" else None
        f = r.reactions[j.id][j.links[1]]
        want = complex(f["x"][k], f["y"][k])
        got = [complex(u, v) for u, v in zip(quiver.U, quiver.V, strict=True)]
        assert min(abs(g - want) for g in got) <= 1e-6 * max(1.0, abs(want)), j.id
        if z is not None:
            assert any(abs(complex(*p) - z) < 1e-9 for p in quiver.get_offsets())
    assert artists(ax, "inertia") == [] and artists(ax, "loads") == []
    orders.clear()
    scene = scene_at(model, q=1.0, layers=("inertia", "loads"), speed=10.0)
    assert orders[0] == 2
    ax = draw_scene(scene)
    assert one(ax, "inertia") and one(ax, "loads")
    couples = [a.get_text() for a in artists(ax, "couple")]
    assert any(t.startswith("M (1) = -10") for t in couples)  # the file's couple -M, M = 10


def test_force_layers_need_dynamics_data():
    with pytest.raises(MechanismError, match="inertia: the file has no dynamics data"):
        scene_at(model_of("slider-crank"), layers=("reactions",))


def test_notebook_reprs_are_small():
    # their speed is measured in benchmarks/bench_plot.py, not here
    from mjstruct.report import structural_report

    engine = read_mechanism(example_path("kin-radial-engine-5"))
    svg = engine._repr_svg_()
    assert svg.startswith("<?xml") and "<svg" in svg and len(svg) < 80_000
    chain = read_mechanism(example_path("watt"))  # no geometry: an atlas panel
    assert "<svg" in chain._repr_svg_()
    r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=24, checks=False)
    assert "<svg" in r._repr_svg_()
    table = structural_report(engine)._repr_html_()
    assert table.startswith("<table>") and "<th style='text-align:left'>MJA</th>" in table


def _distance(a, b) -> float:
    from matplotlib.colors import to_rgb

    return float(np.linalg.norm(np.subtract(to_rgb(a), to_rgb(b))))


def test_vectors_stand_out_from_every_link_colour():
    # the README picture: B3's velocity arrow used to vanish on its green (tab:green) block
    from mjstruct.plot.drawing import DRIVER_COLOUR, FORCE_COLOURS, GROUP_COLOURS

    scene = scene_at(model_of("kin-radial-engine-5"), 1.2, ("assur", "velocity", "acceleration"))
    ax = draw_scene(scene)
    drawn = [a.get_facecolor() for a in artists(ax, "link") if isinstance(a, Polygon)]
    drawn += [a.get_color() for a in artists(ax, "link") if not isinstance(a, Polygon)]
    drawn += [a.get_facecolor() for a in artists(ax, "joint") if isinstance(a, Polygon)]
    assert len(drawn) == 6 + 5  # crank and rods as links, the pistons as their blocks
    for layer in ("velocity", "acceleration"):
        quiver = one(ax, layer)
        face = quiver.get_facecolor()[0]
        assert min(_distance(face, c) for c in drawn) > 0.3, layer
        assert _distance(quiver.get_edgecolor()[0], "white") == 0  # a halo
    vectors = [one(ax, "velocity").get_facecolor()[0], one(ax, "acceleration").get_facecolor()[0]]
    vectors += list(FORCE_COLOURS.values())
    for v in vectors:
        assert min(_distance(v, c) for c in (*GROUP_COLOURS, DRIVER_COLOUR)) > 0.3
    assert min(_distance(a, b) for i, a in enumerate(vectors) for b in vectors[i + 1 :]) > 0.3


def _boxes(ax, *gids):
    fig = ax.figure
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    return [a.get_window_extent(r) for g in gids for a in artists(ax, g)]


def test_scale_bar_and_keys_sit_below_the_mechanism():
    # four-bar.json: the bar used to lie on O1's ground hatching
    scene = scene_at(model_of("four-bar"), layers=("velocity", "acceleration", "paths"))
    ax = draw_scene(scene)
    mechanism = _boxes(ax, "ground", "link", "joint", "driver", "label", "path", "point")
    footer = _boxes(ax, "scalebar")
    footer += [k.text.get_window_extent() for k in artists(ax, "key")]
    assert len(footer) == 2 + 2 and len(mechanism) > 10
    top = max(b.y1 for b in footer)
    assert top < min(b.y0 for b in mechanism)
    y0 = scene.limits[2]
    assert scene.footer > 0 and y0 + scene.footer < min(
        min(z.imag for z in scene.paths[p][:-1]) for p in scene.paths
    )


def test_force_layers_have_one_key_each_and_couples_below():
    scene = scene_at(
        model_of("slider-crank-seed000-dynamics"), 1.0, ("loads", "inertia", "reactions"), 10.0
    )
    ax = draw_scene(scene)
    keys = {k.get_gid(): k for k in artists(ax, "key")}
    assert set(keys) == {"key:loads", "key:inertia", "key:reactions"}
    for layer in ("loads", "inertia", "reactions"):
        key, quiver = keys[f"key:{layer}"], one(ax, layer)
        assert key.text.get_text().startswith(layer)
        assert _distance(key.text.get_color(), quiver.get_facecolor()[0]) == 0
    # one scale for every force: the keys have one length
    assert len({k.U for k in keys.values()}) == 1
    # couples: an arc at the link, the value in the footer below the drawing
    couples = [c for c in artists(ax, "couple") if not c.get_gid().endswith(":sense")]
    assert {c.get_gid() for c in couples} == {"couple:loads:1", "couple:inertia:1"}
    assert all(c.get_text().startswith(("M (1) = ", "-J ε (2) = ")) for c in couples)
    # each value with its sense of turning where the keys have their arrows
    senses = [c.get_text() for c in artists(ax, "couple") if c.get_gid().endswith(":sense")]
    assert len(senses) == 2 and set(senses) <= {"↺", "↻"}
    assert len(artists(ax, "torque")) == len(couples)
    bottom = min(b.y0 for b in _boxes(ax, "link", "joint", "ground"))
    assert all(b.y1 < bottom for b in _boxes(ax, "couple"))


def test_paths_close_over_a_periodic_cycle():
    # fourbar-ms4: the crank circle lacked its last segment
    scene = scene_over_cycle(model_of("fourbar-ms4"), 12, ("paths",), paths=["A"])
    a = scene.paths["A"]
    assert len(a) == 13 and a[-1] == a[0]
    assert len(artists(draw_scene(scene, 3), "path:A")[0].get_xdata()) == 13
    still = scene_at(model_of("four-bar"), layers=("paths",), paths=["A"])
    assert still.paths["A"][-1] == still.paths["A"][0]
    # a slide is not a cycle: its path stays open
    slide = scene_over_cycle(model_of("slider-crank", ["B"]), 12, ("paths",), paths=["A"])
    assert len(slide.paths["A"]) == 12
