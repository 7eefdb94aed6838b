"""``mjstruct draw``, ``animate`` and ``plot``: files written whole or not at all, frame
counts read back, bad input as one line with exit 2; charts and atlas sheets."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import json
import math
import os

import matplotlib.pyplot as plt
import numpy as np
import pytest
from PIL import Image

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot import animation as animation_module
from mjstruct.plot.atlas_sheet import (
    ChainLayout,
    atlas_figures,
    chain_layout,
    crossings,
    draw_chain,
    overlaps,
    quality,
    write_atlas_sheet,
)
from mjstruct.plot.charts import CHARTS, draw_chart, jacobian_determinant, near_singular
from mjstruct.plot.files import write_atomically


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def ex(name: str) -> str:
    return str(example_path(name))


def fails_cleanly(capsys, tmp_path, argv, message):
    before = set(os.listdir(tmp_path))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err, err
    assert "Traceback" not in err
    assert set(os.listdir(tmp_path)) == before  # nothing written, no temporary left


def test_draw_writes_each_format(tmp_path, capsys):
    for suffix in ("svg", "png", "pdf"):
        out = tmp_path / f"engine.{suffix}"
        argv = ["draw", ex("kin-radial-engine-5"), "--show", "assur,velocity", "-o", str(out)]
        assert main(argv) == 0
        assert out.stat().st_size > 1000
    assert (tmp_path / "engine.svg").read_text().lstrip().startswith("<?xml")
    assert (tmp_path / "engine.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "engine.pdf").read_bytes()[:4] == b"%PDF"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--show", "speed"], "--show: unknown layer 'speed'"),
        (["--q", "1,2"], "--q: expected 1 finite value(s)"),
        (["--q", "x"], "--q: expected numbers"),
        (["--q", "12grad"], "--q: expected numbers Q1,Q2 (angles may end in deg or rad)"),
        (["--paths", "Z"], "--paths: 'Z' is neither"),
        (["--drivers", "Q"], "--drivers: 'Q' is not a joint id"),
    ],
)
def test_draw_bad_input(tmp_path, capsys, args, message):
    out = str(tmp_path / "x.svg")
    fails_cleanly(capsys, tmp_path, ["draw", ex("slider-crank"), *args, "-o", out], message)


@pytest.mark.parametrize("command", ["draw", "animate", "plot"])
def test_bad_output_paths(tmp_path, capsys, command):
    extra = ["--what", "angles"] if command == "plot" else []
    argv = [command, ex("four-bar"), *extra, "-o"]
    fails_cleanly(capsys, tmp_path, [*argv, str(tmp_path / "x.bmp")], "-o: no writer for '.bmp'")
    fails_cleanly(capsys, tmp_path, [*argv, str(tmp_path / "x")], "-o: no writer for a file")
    (tmp_path / "file").write_text("")
    out = str(tmp_path / "file" / "x.svg")
    fails_cleanly(
        capsys,
        tmp_path,
        [*argv, out.replace(".svg", ".gif" if command == "animate" else ".svg")],
        "-o: cannot write",
    )


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["draw", ex("four-bar"), "-o", "/proc/a.png"], "-o"),
        (["animate", ex("four-bar"), "--frames", "3", "-o", "/proc/x.gif"], "-o"),
        (["plot", ex("four-bar"), "--what", "angles", "-o", "/sys/x.png"], "-o"),
        (["atlas", "--dof", "1", "--links", "6", "--draw", "/proc/x.pdf"], "--draw"),
        (["draw", ex("watt"), "-o", "/proc/w.svg"], "-o"),
    ],
)
def test_unwritable_directories_are_refused(tmp_path, capsys, argv, flag):
    # the tests run as root, for whom a chmod 0o500 directory stays writable: /proc and
    # /sys refuse new files to everyone, while os.access says they are writable
    out = argv[-1]
    fails_cleanly(capsys, tmp_path, argv, f"{flag}: cannot write {out} (cannot create")
    assert not os.path.exists(out)


def test_a_directory_gone_before_writing_is_a_clean_error(tmp_path):
    gone = tmp_path / "gone"
    gone.mkdir()
    target = str(gone / "x.png")
    gone.rmdir()  # after the check, before the write
    with pytest.raises(MechanismError, match=r"^-o: cannot write .*x\.png \(No such file"):
        write_atomically(target, lambda tmp: None, name="-o")
    assert os.listdir(tmp_path) == []


def test_mp4_needs_ffmpeg(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(animation_module, "ffmpeg_available", lambda: False)
    argv = ["animate", ex("four-bar"), "--frames", "4", "-o", str(tmp_path / "a.mp4")]
    fails_cleanly(capsys, tmp_path, argv, "-o: writing .mp4 needs ffmpeg")


def test_a_failed_write_leaves_nothing(tmp_path):
    target = tmp_path / "out.png"

    def broken(tmp: str) -> None:
        with open(tmp, "w") as f:
            f.write("half a picture")
        raise OSError(28, "No space left on device")

    with pytest.raises(MechanismError, match="cannot write"):
        write_atomically(str(target), broken)
    assert os.listdir(tmp_path) == []
    target.write_text("old")
    with pytest.raises(MechanismError):
        write_atomically(str(target), broken)
    assert os.listdir(tmp_path) == ["out.png"] and target.read_text() == "old"


def test_gif_has_n_frames(tmp_path, capsys):
    out = tmp_path / "engine.gif"
    argv = ["animate", ex("kin-radial-engine-5"), "--frames", "7", "--show", "velocity",
            "--dpi", "30", "-o", str(out)]  # fmt: skip
    assert main(argv) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 7
    assert capsys.readouterr().err == ""  # no progress bar off a terminal


def test_html_holds_n_frames_and_stands_alone(tmp_path):
    out = tmp_path / "four-bar.html"
    assert main(["animate", ex("four-bar"), "--frames", "6", "--dpi", "30", "-o", str(out)]) == 0
    page = out.read_text()
    assert page.count("data:image/png;base64") == 6
    assert "<button" in page or "onclick" in page  # play controls
    assert os.listdir(tmp_path) == ["four-bar.html"]  # no frame folder beside it


def test_animation_notes_gaps(tmp_path, capsys):
    f = tmp_path / "rocker.json"
    f.write_text(
        '{"frame": "0", "drivers": ["O1"], "joints": ['
        '{"id": "O1", "links": ["0", "1"], "at": [0, 0]},'
        '{"id": "A", "links": ["1", "2"], "at": [0, 2]},'
        '{"id": "B", "links": ["2", "3"], "at": [1, 2]},'
        '{"id": "O2", "links": ["3", "0"], "at": [2.6, 0]}]}'
    )
    out = tmp_path / "rocker.gif"
    assert main(["animate", str(f), "--frames", "12", "--dpi", "30", "-o", str(out)]) == 0
    with Image.open(out) as gif:
        assert gif.n_frames == 12
    assert "frames do not assemble (drawn as gaps)" in capsys.readouterr().err


@pytest.fixture
def orders(monkeypatch):
    asked: list[int] = []
    original = KinematicModel.motion

    def recording(self, q, order=2, *args, **kwargs):
        asked.append(order)
        return original(self, q, order, *args, **kwargs)

    monkeypatch.setattr(KinematicModel, "motion", recording)
    return asked


@pytest.mark.parametrize(("what", "order"), [("angles", 0), ("omega", 1), ("eps", 2),
                                             ("paths", 0), ("jacobian", 0)])  # fmt: skip
def test_charts_compute_only_what_they_show(orders, what, order):
    model = KinematicModel.build(read_mechanism(example_path("slider-crank")))
    fig = draw_chart(model, what, frames=24)
    assert orders == [order]
    assert any(ax.get_lines() for ax in fig.axes)


def plotted_at(line, x: np.ndarray) -> np.ndarray:
    """The line's y where its x equals each of ``x`` (each must be plotted)."""
    xs, ys = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
    out = []
    for v in x:
        (hit,) = np.flatnonzero(np.isclose(xs, v, rtol=0, atol=1e-9) & np.isfinite(ys))[:1]
        out.append(ys[hit])
    return np.array(out)


def test_omega_chart_is_sigma_times_speed():
    from mjstruct.kinematics.solver import kinematic_analysis

    m = read_mechanism(example_path("slider-crank"))
    r = kinematic_analysis(m, frames=24, speed=3.0, checks=False)
    # radians: the cycle as the kinematics runs it, from the reference
    fig = draw_chart(r.model, "omega", frames=24, speed=3.0, radians=True)
    line = next(ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "link:2")
    assert np.allclose(line.get_ydata(), r.links["2"]["omega"], rtol=1e-12, atol=1e-12)
    assert np.allclose(line.get_xdata(), r.q[:, 0])
    assert "(rad)" in fig.axes[0].get_xlabel()
    # the default: the crank angle from 0 to 360°, every frame at its angle
    fig = draw_chart(r.model, "omega", frames=24, speed=3.0)
    ax = fig.axes[0]
    line = next(ln for ln in ax.get_lines() if ln.get_gid() == "link:2")
    phi = np.degrees(r.q[:, 0]) % 360
    assert np.allclose(plotted_at(line, phi), r.links["2"]["omega"], rtol=1e-12, atol=1e-12)
    x = np.asarray(line.get_xdata(), float)
    assert np.all(np.diff(x[np.isfinite(x)]) > 0) and ax.get_xlim() == (0.0, 360.0)
    assert "(°)" in ax.get_xlabel()
    # continued across 360°: the curve reaches both ends of the axis
    assert x[0] < 0 < 360 < x[-1]


def test_angle_chart_in_degrees_keeps_a_swing_whole_and_breaks_a_full_turn():
    m = read_mechanism(example_path("four-bar"))
    model = KinematicModel.build(m)
    fig = draw_chart(model, "angles", frames=72)
    lines = {ln.get_gid(): ln for ln in fig.axes[0].get_lines()}
    motion = model.motion(model.sweep(72), order=0)
    phi = np.degrees(motion.q[:, 0]) % 360
    for link, line in lines.items():
        want = np.degrees(motion.angle(link.split(":")[1])[0])
        got = plotted_at(line, phi)
        # the same angle up to whole turns
        assert np.allclose(np.mod(got - want + 180, 360) - 180, 0, atol=1e-9)
        y = np.asarray(line.get_ydata(), float)
        steps = np.abs(np.diff(y))
        assert np.nanmax(steps) < 30  # no vertical line at a wrap
    # the crank turns: its angle runs with the crank angle from 0 to 360°, in one
    # piece on the axis; the rocker swings: in one piece
    crank = np.asarray(lines["link:1"].get_ydata(), float)
    x = np.asarray(lines["link:1"].get_xdata(), float)
    on_axis = (x >= 0) & (x <= 360)
    assert not np.isnan(crank[on_axis]).any()
    assert np.allclose(np.diff(crank[on_axis]), np.diff(x[on_axis]), atol=1e-9)
    rocker = np.asarray(lines["link:3"].get_ydata(), float)
    assert not np.isnan(rocker).any()


def parallelogram() -> KinematicModel:
    return KinematicModel.build(mechanism_from_dict({
        "frame": "0", "drivers": ["O1"], "joints": [
            {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
            {"id": "A", "links": ["1", "2"], "at": [0, 1]},
            {"id": "B", "links": ["2", "3"], "at": [2, 1]},
            {"id": "O2", "links": ["3", "0"], "at": [2, 0]}]}))  # fmt: skip


def test_jacobian_chart_shades_near_singular_frames():
    model = parallelogram()
    fig = draw_chart(model, "jacobian", frames=72)
    ax = fig.axes[0]
    spans = [p for p in ax.patches if p.get_gid() == "singular"]
    motion = model.motion(model.sweep(72), order=0)
    det = jacobian_determinant(motion)
    # the parallelogram folds flat at q = 0 and π: the determinant vanishes there
    assert near_singular(det).sum() >= 2
    assert len(spans) >= 2
    q = motion.q[:, 0] % (2 * np.pi)
    flat = np.minimum(np.abs(np.sin(q)), 1.0)
    assert (flat[near_singular(det)] < 0.1).all()


def test_transmission_angle_is_a_four_bar_chart(tmp_path, capsys):
    fig = draw_chart(parallelogram(), "transmission", frames=36)
    y = fig.axes[0].get_lines()[0].get_ydata()
    assert np.nanmin(y) >= 0 and np.nanmax(y) <= 180
    # parallelogram: coupler ∥ frame, so the angle at B equals the crank angle's supplement
    assert np.nanmax(y) > 170 and np.nanmin(y) < 10
    out = str(tmp_path / "t.svg")
    fails_cleanly(
        capsys,
        tmp_path,
        ["plot", ex("slider-crank"), "--what", "transmission", "-o", out],
        "--what: the transmission angle needs a four-bar",
    )


def test_plot_bad_chart(tmp_path, capsys):
    out = str(tmp_path / "x.svg")
    fails_cleanly(capsys, tmp_path, ["plot", ex("four-bar"), "--what", "speed", "-o", out],
                  "--what: unknown chart 'speed'")  # fmt: skip
    fails_cleanly(capsys, tmp_path, ["plot", ex("four-bar"), "--what", "V", "-o", out],
                  "inertia: the file has no dynamics data")  # fmt: skip


def test_dynamics_charts_plot_the_dynamics_result():
    from mjstruct.dynamics import dynamic_analysis

    m = read_mechanism(example_path("slider-crank-seed000-dynamics"))
    model = KinematicModel.build(m)
    free = dynamic_analysis(m, qdot0=10.0, frames=36)
    fig = draw_chart(model, "qdot", frames=36, speed=10.0, radians=True)
    assert np.allclose(fig.axes[0].get_lines()[0].get_ydata(), free.qdot[:, 0])
    phi = np.degrees(free.q[:, 0]) % 360
    fig = draw_chart(model, "qdot", frames=36, speed=10.0)
    assert np.allclose(plotted_at(fig.axes[0].get_lines()[0], phi), free.qdot[:, 0])
    steady = dynamic_analysis(m, speed=10.0, frames=36, outputs=("reactions",))
    fig = draw_chart(model, "reactions", frames=36, speed=10.0)
    lines = {ln.get_gid(): ln for ln in fig.axes[0].get_lines()}
    r = steady.reactions["B"]["3"]
    assert np.allclose(plotted_at(lines["reaction:B:3"], phi), np.hypot(r["x"], r["y"]))
    assert set(CHARTS) >= {"V", "Q", "qdot", "qddot", "reactions"}


def test_atlas_sheet_one_panel_per_chain_and_no_crossings(tmp_path):
    from mjstruct.synthesis.atlas import atlas

    a = atlas(1, 8, mj=True)
    for k, c in enumerate(a.chains, 1):
        lay = chain_layout(c.mechanism())
        assert lay.planar == c.planar
        if c.planar:
            # no crossing edges, no link drawn over another (polygons sharing area, a
            # polygon as the outer face covering the chain), no joint on a foreign bar,
            # no two bars through a multiple joint in line
            assert crossings(lay) == 0, k
            assert overlaps(lay) == [], k
            assert quality(lay) > 0.5, k
    some = a.chains[10:22]  # simple and MJ chains
    figs = atlas_figures(some, per_page=5)
    panels = [ax for fig in figs for ax in fig.axes]
    assert len(figs) == 3 and len(panels) == len(some)
    titles = [ax.get_title() for ax in panels]
    assert titles[0].startswith("1\n[LA] ") and titles[-1].startswith(f"{len(some)}\n")
    assert sum("[MJA] -" not in t for t in titles) == sum(bool(c.MJA) for c in some) > 0
    out = tmp_path / "atlas.svg"
    assert write_atlas_sheet(a.chains[:4], str(out)) == 1
    pdf = tmp_path / "atlas.pdf"
    assert write_atlas_sheet(a.chains[:7], str(pdf), per_page=3) == 3
    fig = plt.figure()
    ax = fig.add_subplot()
    m = a.chains[-1].mechanism()
    draw_chain(ax, m)
    mj = [j for j in m.joints if j.is_multiple]
    marks = [c for c in ax.collections if (c.get_gid() or "").startswith("mj:")]
    assert len(marks) == len(mj) >= 1
    assert all(len(c.get_offsets()) == len(m.joint(c.get_gid()[3:]).links) for c in marks)


def test_atlas_sheet_panels(tmp_path):
    from mjstruct.synthesis.atlas import atlas

    chains = atlas(1, 8).chains
    figs_before = set(plt.get_fignums())
    write_atlas_sheet(chains[:3], str(tmp_path / "a.png"))
    assert set(plt.get_fignums()) == figs_before  # closed
    # a crossing drawing is detected (the check is not vacuous)
    lay = chain_layout(chains[0].mechanism())
    a, b = lay.edges()[0]
    far = next(e for e in lay.edges() if not {a, b} & set(e))
    pos = dict(lay.pos)
    pos[a], pos[far[0]] = lay.pos[far[0]], lay.pos[a]
    swapped = type(lay)(pos, lay.outline, lay.planar)
    assert crossings(swapped) > 0


def test_atlas_layout_checks_are_not_vacuous():
    from mjstruct.synthesis.atlas import atlas

    chains = atlas(1, 8, mj=True).chains
    # F1n8-0016, [LA] 6,0,2: a quaternary link's polygon as the outer face covered the
    # whole chain, the other quaternary inside it
    m = chains[15].mechanism()
    lay = chain_layout(m)
    quads = [link for link, js in lay.outline.items() if len(js) == 4]
    assert len(quads) == 2
    from mjstruct.plot import atlas_sheet

    jg = atlas_sheet._joint_graph(m, lay.outline)
    pos = atlas_sheet._barycentric(jg, list(lay.outline[quads[0]]))  # the old choice
    covered = ChainLayout(pos, lay.outline, True)
    assert crossings(covered) == 0 and (quads[0], quads[1]) in overlaps(covered)
    # two triangles sharing a joint, one in the other's corner
    tri = ChainLayout(
        {"A": 0j, "B": 1 + 0j, "C": 1j, "D": 0.3 + 0.1j, "E": 0.1 + 0.3j},
        {"1": ("A", "B", "C"), "2": ("A", "D", "E")},
        True,
    )
    assert crossings(tri) == 0 and ("1", "2") in overlaps(tri)
    # F1n8-0059: the bars in parallel between its two multiple joints were piled up
    # and two bars ran in line through a multiple joint
    lay = chain_layout(chains[58].mechanism())
    assert quality(lay) >= 1.0
    pos = dict(lay.pos)
    a, b = "J1", "J0"
    other = next(j for js in lay.outline.values() if a in js for j in js if j not in (a, b))
    pos[other] = pos[a] + (pos[a] - pos[b]) * 0.5  # in line with the bar a–b
    assert quality(ChainLayout(pos, lay.outline, True)) < 0.1


def test_atlas_title_above_the_captions():
    from mjstruct.synthesis.atlas import atlas

    (fig,) = atlas_figures(atlas(1, 6).chains, title="F = 1, n = 6")
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    title = fig._suptitle.get_window_extent(r)
    captions = [ax.title.get_window_extent(r) for ax in fig.axes]
    assert len(captions) >= 2 and title.y0 > max(c.y1 for c in captions)


def test_atlas_sheet_bad_suffix(tmp_path):
    with pytest.raises(MechanismError, match="path: no writer"):
        write_atlas_sheet([], str(tmp_path / "a.gif"))


def test_atlas_draw_flag(tmp_path, capsys):
    import re

    out = tmp_path / "atlas.pdf"
    assert main(["atlas", "--links", "8", "--draw", str(out)]) == 0
    pdf = out.read_bytes()
    assert pdf[:4] == b"%PDF" and len(re.findall(rb"/Type\s*/Page[^s]", pdf)) == 1
    capsys.readouterr()
    fails_cleanly(capsys, tmp_path, ["atlas", "--links", "8", "--draw", str(tmp_path / "a.gif")],
                  "--draw: no writer for '.gif'")  # fmt: skip


def test_ms_diagram_chart_marks_the_four_bar():
    from mjstruct.plot.ms_diagram import ms_point

    model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    fig = draw_chart(model, "ms-diagram")
    _, p2, p3 = ms_point(model.mechanism)
    star = [ln for ln in fig.axes[0].get_lines() if ln.get_marker() == "*"]
    assert len(star) == 1 and tuple(star[0].get_xydata()[0]) == pytest.approx((p2, p3))


def test_singular_zones_are_drawn_on_the_scheme():
    from mjstruct.plot.drawing import artists
    from mjstruct.plot.ms_diagram import plot_singular_zones
    from mjstruct.singular.analysis import singular_analysis

    m = read_mechanism(example_path("fourbar-ms4"))
    analysis = singular_analysis(m, clearance=0.02)
    fig = plot_singular_zones(m, analysis)
    (ax,) = fig.axes
    # the mechanism's scheme (pins, ground) at the first position, the others outlined
    assert len(artists(ax, "joint")) == len(m.joints) and artists(ax, "ground")
    assert {a.get_gid().rsplit(":", 1)[0] for a in artists(ax, "position")} == {
        "position:1",
        "position:2",
    }
    # one wedge and one ψ note per zone
    zones = [z for p in analysis.singular for z in p.zone or () if z.psi is not None]
    values = [a for a in artists(ax, "psi") if not a.get_gid().endswith(":mark")]
    marks = [a for a in artists(ax, "psi") if a.get_gid().endswith(":mark")]
    assert len(artists(ax, "zone")) == len(values) == len(marks) == len(zones) >= 3
    assert [a.get_text() for a in marks] == [f"ψ{n}" for n in range(1, len(zones) + 1)]
    assert all(a.get_text().startswith(f"ψ{n} = ") for n, a in enumerate(values, 1))


def test_draw_without_geometry_is_the_structural_scheme(tmp_path, capsys):
    out = tmp_path / "watt.svg"
    assert main(["draw", ex("watt"), "-o", str(out)]) == 0
    svg = out.read_text()
    assert "structural scheme" in svg
    fails_cleanly(
        capsys,
        tmp_path,
        ["draw", ex("watt"), "--show", "velocity", "-o", str(tmp_path / "w.svg")],
        "--show: needs joint centres",
    )


def test_json_summaries(tmp_path, capsys):
    import json

    out = tmp_path / "a.gif"
    argv = ["animate", ex("four-bar"), "--frames", "5", "--dpi", "20", "--json", "-o", str(out)]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert d == {"output": str(out), "frames": 5, "layers": [], "gaps": [],
                 "branch_points": [], "warnings": []}  # fmt: skip
    argv = ["draw", ex("slider-crank"), "--q", "2", "--json", "-o", str(tmp_path / "d.svg")]
    assert main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["q"] == [2.0] and d["assembles"] is True


def test_progress_bar_only_on_a_terminal(tmp_path, monkeypatch, capsys):
    import io
    import sys

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    term = Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    argv = [
        "animate",
        ex("four-bar"),
        "--frames",
        "3",
        "--dpi",
        "20",
        "-o",
        str(tmp_path / "a.gif"),
    ]
    assert main(argv) == 0
    assert "3/3" in term.getvalue() and term.getvalue().startswith("\ranimate")
    term2 = Terminal()
    monkeypatch.setattr(sys, "stderr", term2)
    assert main([*argv[:-2], "--json", "-o", str(tmp_path / "b.gif")]) == 0
    assert term2.getvalue() == ""  # never with --json


def test_each_command_says_in_one_line_what_it_wrote_where(tmp_path, capsys):
    cases = [
        (["draw", ex("slider-crank"), "--q", "1", "--show", "velocity"], "d.svg",
         "(slider-crank ([Slider-crank Mathcad]) at q = 57.3°, layers velocity)"),
        (["draw", ex("watt")], "w.png", "(structural scheme of Watt six-bar)"),
        (["animate", ex("four-bar"), "--frames", "4", "--dpi", "20"], "a.gif",
         "(4 frames, 0.2 s at 20 fps)"),
        (["plot", ex("four-bar"), "--what", "omega", "--frames", "24"], "p.png",
         "(chart omega of four-bar, 24 frames)"),
    ]  # fmt: skip
    for argv, name, what in cases:
        out = tmp_path / name
        assert main([*argv, "-o", str(out)]) == 0
        printed = capsys.readouterr()
        assert printed.out == f"wrote {out} {what}\n" and printed.err == ""
        assert out.exists()
    # warnings stay on stderr, after the one line on stdout
    rocker = tmp_path / "rocker.json"
    rocker.write_text(
        '{"frame": "0", "drivers": ["O1"], "joints": ['
        '{"id": "O1", "links": ["0", "1"], "at": [0, 0]},'
        '{"id": "A", "links": ["1", "2"], "at": [0, 2]},'
        '{"id": "B", "links": ["2", "3"], "at": [1, 2]},'
        '{"id": "O2", "links": ["3", "0"], "at": [2.6, 0]}]}'
    )
    out = tmp_path / "r.gif"
    assert main(["animate", str(rocker), "--frames", "12", "--dpi", "20", "-o", str(out)]) == 0
    printed = capsys.readouterr()
    assert printed.out.count("\n") == 1 and printed.out.startswith(f"wrote {out} (12 frames")
    assert "frames do not assemble" in printed.out and "warning:" in printed.err


def test_q_takes_its_unit_and_says_how_a_bare_number_is_read(tmp_path, capsys):
    # issue 38.2: --q 45 meant 45 radians, silently; a suffix states the unit, a bare
    # number stays radians (the documented behaviour) and, beyond a turn, is warned about
    out = str(tmp_path / "d.svg")

    def drawn(q: str) -> tuple[list[float], list[str], str]:
        assert main(["draw", ex("four-bar"), "--q", q, "--json", "-o", out]) == 0
        d = json.loads(capsys.readouterr().out)
        assert main(["draw", ex("four-bar"), "--q", q, "-o", out]) == 0
        return d["q"], d["warnings"], capsys.readouterr().out

    q, warnings, line = drawn("90deg")
    assert q == pytest.approx([math.pi / 2]) and not warnings and "at q = 90.0°" in line
    assert drawn("90°")[0] == pytest.approx([math.pi / 2])
    assert drawn("0.8rad")[0] == drawn("0.8")[0] == pytest.approx([0.8])
    q, warnings, line = drawn("45")
    assert q == [45.0] and "at q = 58.3°" in line
    assert len(warnings) == 1 and "taken as radians" in warnings[0] and "45deg" in warnings[0]
    # a slide takes lengths only
    argv = ["draw", ex("scotch-yoke"), "--drivers", "G", "--q", "0.1deg", "-o", out]
    assert main(argv) == 2
    assert "--q: driver G is a slide, in the file's length unit" in capsys.readouterr().err
    # the help says the unit
    with pytest.raises(SystemExit):
        main(["draw", "--help"])
    assert "45deg" in capsys.readouterr().out
