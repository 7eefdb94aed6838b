"""Animations: artists built once and moved per frame, frames composed from a background
and sprites as matplotlib would draw them, one palette for every GIF frame."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from PIL import Image

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.animation import FrameRenderer, write_animation
from mjstruct.plot.drawing import artists, scene_over_cycle


def scene_of(name: str, frames: int, layers: tuple[str, ...] = ()):
    model = KinematicModel.build(read_mechanism(example_path(name)))
    return scene_over_cycle(model, frames, layers)


def full_draw(renderer: FrameRenderer, k: int) -> np.ndarray:
    """Frame ``k`` drawn by matplotlib alone: every artist, labels and keys included."""
    renderer.drawing.show(k)
    renderer.canvas.draw()
    return np.asarray(renderer.canvas.buffer_rgba())[..., :3].astype(int)


@pytest.mark.parametrize(
    ("name", "layers"),
    [("kin-radial-engine-5", ("velocity",)), ("slider-crank", ("paths", "acceleration"))],
)
def test_frames_are_what_matplotlib_draws(name, layers):
    scene = scene_of(name, 8, layers)
    renderer = FrameRenderer(scene, dpi=60)
    composed = [renderer.frame(k) for k in range(8)]
    for k in (0, 3, 6):
        ref = full_draw(renderer, k)
        diff = np.abs(ref - composed[k].astype(int)).max(axis=2)
        # the labels are pasted on whole pixels: a few edge pixels differ, nothing else
        assert (diff > 64).mean() < 0.004, (k, (diff > 64).sum())
        assert np.abs(ref - composed[k]).mean() < 0.5
    # the mechanism moves: frames differ where the links are
    assert np.abs(composed[0].astype(int) - composed[3]).max() > 100


def test_artists_are_built_once():
    scene = scene_of("kin-radial-engine-5", 12, ("velocity",))
    renderer = FrameRenderer(scene, dpi=40)
    ax = renderer.drawing.ax
    children = list(ax.get_children())
    centres = []
    for k in range(12):
        renderer.frame(k)
        (pin,) = artists(ax, "joint:B1")
        centres.append(pin.get_center())
    assert ax.get_children() == children  # nothing added, nothing removed
    # the same pin artist moved with the kinematics
    b1 = scene.motion.centre("B1")[0]
    assert np.allclose([complex(*c) for c in centres], b1[:12])


def test_gap_frames_hide_the_scheme_and_show_the_note(tmp_path):
    from mjstruct.io import mechanism_from_dict

    rocker = mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
                {"id": "A", "links": ["1", "2"], "at": [0, 2]},
                {"id": "B", "links": ["2", "3"], "at": [1, 2]},
                {"id": "O2", "links": ["3", "0"], "at": [2.6, 0]},
            ],
        }
    )
    scene = scene_over_cycle(KinematicModel.build(rocker), 12)
    gaps = np.flatnonzero(~scene.motion.valid)
    assert gaps.size and (~gaps.astype(bool)).size
    renderer = FrameRenderer(scene, dpi=40)
    ax = renderer.drawing.ax
    renderer.frame(int(gaps[0]))
    assert artists(ax, "link") == [] and len(artists(ax, "note")) == 1
    ok = int(np.flatnonzero(scene.motion.valid)[0])
    renderer.frame(ok)
    assert len(artists(ax, "link")) == 3 and artists(ax, "note") == []
    # a gap frame is the background and the note: no label pasted on it
    ref = full_draw(renderer, int(gaps[0]))
    assert np.abs(ref - renderer.frame(int(gaps[0]))).max() <= 1


def gif_colour_tables(data: bytes) -> tuple[bytes, list[bytes]]:
    """(the global colour table, each image's local table or b""), read from the GIF's
    blocks."""
    assert data[:6] in (b"GIF87a", b"GIF89a")
    packed = data[10]
    size = 3 * 2 ** ((packed & 7) + 1) if packed & 0x80 else 0
    table = data[13 : 13 + size]
    pos = 13 + size
    local = []

    def skip_sub_blocks(p: int) -> int:
        while data[p]:
            p += data[p] + 1
        return p + 1

    while data[pos] != 0x3B:  # trailer
        if data[pos] == 0x21:  # extension: label, then sub-blocks
            pos = skip_sub_blocks(pos + 2)
        else:
            assert data[pos] == 0x2C  # image descriptor
            flags = data[pos + 9]
            size = 3 * 2 ** ((flags & 7) + 1) if flags & 0x80 else 0
            local.append(data[pos + 10 : pos + 10 + size])
            pos += 10 + size
            pos = skip_sub_blocks(pos + 1)  # LZW minimum code size, then data
    return table, local


def test_gif_frames_share_one_palette(tmp_path):
    out = tmp_path / "engine.gif"
    write_animation(scene_of("kin-radial-engine-5", 6, ("velocity",)), str(out), dpi=40)
    table, local = gif_colour_tables(out.read_bytes())
    # every frame's colours are the first frame's (a table repeated, or none)
    assert len(table) >= 3 * 128 and len(local) == 6
    assert all(t in (b"", table) for t in local)
    with Image.open(out) as gif:
        assert gif.n_frames == 6
        rgb = np.asarray(gif.convert("RGB")).reshape(-1, 3).astype(int)
    # the crimson of the driver survives the shared palette (not snapped to grey)
    crimson = np.array([220, 20, 60])
    assert np.abs(rgb - crimson).sum(axis=1).min() < 40


def test_html_page_has_controls_and_every_frame(tmp_path):
    out = tmp_path / "four-bar.html"
    write_animation(scene_of("four-bar", 5), str(out), dpi=30, fps=10)
    page = out.read_text()
    assert page.count("data:image/png;base64,") == 5
    for control in ('id="play"', 'id="pause"', 'id="slider"', 'id="loop"', 'max="4"'):
        assert control in page
    assert "setInterval(step, 100)" in page  # 10 frames per second
