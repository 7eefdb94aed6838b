"""Animations of a scene over one cycle: GIF, self-contained HTML, MP4 (with ffmpeg).

Owns writing a :class:`~mjstruct.plot.drawing.Scene` frame by frame: ``.gif`` (one
palette shared by every frame), ``.html`` (one page with the frames embedded and play,
step and loop controls; nothing beside it) and ``.mp4`` through ffmpeg only when
ffmpeg is installed.  The axes stay fixed over the cycle (the scene's limits); a frame
that does not assemble is drawn as a gap with a note, a frame at a branch point
marks it.  The file appears only when complete.

Speed (:class:`FrameRenderer`): the drawing's artists are built once
(:class:`~mjstruct.plot.drawing.SceneArtists`) and only their data change from frame
to frame; what never changes is drawn once as a background; the labels, whose text
never changes, are drawn by matplotlib once each and pasted at their place in every
frame (text is most of the cost of drawing a frame); a GIF's colours are chosen once
for all frames.

Examples
--------
>>> import matplotlib
>>> matplotlib.use("Agg")
>>> import tempfile, os
>>> from PIL import Image
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> from mjstruct.plot.drawing import scene_over_cycle
>>> scene = scene_over_cycle(KinematicModel.build(read_mechanism(example_path("four-bar"))), 5)
>>> out = os.path.join(tempfile.mkdtemp(), "four-bar.gif")
>>> write_animation(scene, out, dpi=40)
>>> with Image.open(out) as gif:
...     gif.n_frames
5
"""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from mjstruct.errors import MechanismError
from mjstruct.plot.drawing import Scene, SceneArtists
from mjstruct.plot.files import check_output, write_atomically
from mjstruct.plot.layout import drawing_figure
from mjstruct.plot.style import (
    ACCELERATION_COLOUR,
    DRIVER_COLOUR,
    FORCE_COLOURS,
    FRAME_COLOUR,
    GROUP_COLOURS,
    LINK_COLOUR,
    VELOCITY_COLOUR,
)

if TYPE_CHECKING:
    from PIL import Image as PILImage

#: output suffixes an animation can be written to
ANIMATION_SUFFIXES = (".gif", ".html", ".mp4")
#: colours of a GIF's shared palette
GIF_COLOURS = 255
#: colours a drawing uses as they are: a GIF's palette holds them exactly
STYLE_COLOURS = (
    "white",
    "black",
    LINK_COLOUR,
    FRAME_COLOUR,
    DRIVER_COLOUR,
    VELOCITY_COLOUR,
    ACCELERATION_COLOUR,
    *GROUP_COLOURS,
    *FORCE_COLOURS.values(),
    "0.85",  # the frame's pivots
    "0.45",  # paths
)

Pixels = npt.NDArray[np.uint8]


def ffmpeg_available() -> bool:
    """Whether matplotlib finds an ffmpeg executable."""
    from matplotlib import animation

    return bool(animation.writers.is_available("ffmpeg"))


class FrameRenderer:
    """RGB images of a scene's frames, drawn on one figure whose artists are built once.

    What never changes (the frame's pivots, paths, scale bar, legend, the title's name)
    is drawn once as the background.  Each frame then starts from the background and
    matplotlib draws only the artists that change; the labels (ids beside joints,
    links and points: text that only moves) and the vector keys (fixed, shown while
    their layer is) are drawn by matplotlib once each, on a transparent canvas, and
    pasted where matplotlib would draw them.

    Parameters
    ----------
    scene : the scene whose shown frames are drawn.
    dpi : resolution of the images.
    width : figure width in inches.
    radians : the title's driver angles in radians (default: degrees, 0 to 360).
    ax : axes to draw on (default: a figure of its own shaped to the scene); the
        explorer's figure has a second axes below the drawing.
    moving : further artists of the figure drawn anew at every frame (the explorer's
        marker of the driver's value), after the drawing's.
    varying : further artists fixed over the frames but changed with the scene by
        :meth:`rebind` (the explorer's assembly range and singular positions).
    rebindable : whether :meth:`rebind` will be called (the background is then drawn
        in two steps, so that a new scene redraws only what it changes).
    """

    def __init__(
        self,
        scene: Scene,
        dpi: int,
        width: float = 6.0,
        radians: bool = False,
        ax: Any = None,
        moving: Sequence[Any] = (),
        varying: Sequence[Any] = (),
        rebindable: bool = False,
    ) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.scene = scene
        if ax is None:
            self.figure, ax = drawing_figure(scene, width=width, pyplot=False)
        else:
            self.figure = ax.get_figure(root=True)
        self.figure.set_dpi(dpi)
        # matplotlib's canvas methods are untyped
        self.canvas = cast(Any, FigureCanvasAgg(self.figure))
        self.drawing = SceneArtists(ax, scene, radians=radians)
        self.changing = self.drawing.changing
        self.labels = self.drawing.labels
        self.keys = self.drawing.keys
        self.moving = list(moving)
        self.varying = list(varying)
        self.rebindable = rebindable
        self.drawing.show(int(scene.shown[0]))
        self.capture_background()
        # sprites: (pixels, column and row of their top-left pixel from the anchor pixel)
        self.label_sprites = [self._label_sprite(label) for label in self.labels]
        self.key_sprites = [self._sprite(key, (0, 0)) for key in self.keys]

    @property
    def rebound(self) -> list[Any]:
        """The background's artists that :meth:`rebind` changes (the frame's pivots,
        the paths, :attr:`varying`), in z-order."""
        scheme = self.drawing.scheme
        found = [a for pair in scheme.grounds.values() for a in pair]
        found += [*scheme.path_lines.values(), *self.varying]
        return sorted(found, key=lambda a: a.get_zorder())

    def capture_background(self) -> None:
        """Draw what never changes and keep its pixels as the background of every frame.

        Every artist but the moving ones, the labels and the keys; when
        :attr:`rebindable`, in two steps: the static part (also without
        :attr:`rebound`: the title, the scale bar, axes and their ticks) is drawn once by
        matplotlib, and :attr:`rebound` over it, which :meth:`rebind` draws again."""
        hidden = [*self.changing, *self.labels, *self.keys, *self.moving]
        if self.rebindable:
            hidden += self.rebound
        visible = [a.get_visible() for a in hidden]
        for a in hidden:
            a.set_visible(False)
        self.canvas.draw()
        self.static = self.canvas.copy_from_bbox(self.figure.bbox)
        for a, v in zip(hidden, visible, strict=True):
            a.set_visible(v)
        if self.rebindable:
            self._draw_rebound()
        else:
            self.background = self.static

    def _draw_rebound(self) -> None:
        self.canvas.restore_region(self.static)
        renderer = self.canvas.get_renderer()
        for a in self.rebound:
            a.draw(renderer)
        self.background = self.canvas.copy_from_bbox(self.figure.bbox)

    def rebind(self, scene: Scene) -> None:
        """Draw ``scene`` from now on (:meth:`SceneArtists.rebind
        <mjstruct.plot.drawing.SceneArtists.rebind>`: the same mechanism with other joint
        centres, within the axes' limits): the artists and the labels' sprites are kept;
        only the background's :attr:`rebound` artists are drawn again."""
        if not self.rebindable:
            raise ValueError("rebind: the renderer was not made rebindable")
        self.drawing.rebind(scene)
        self.scene = scene
        self._draw_rebound()

    def _pixel(self, label: Any) -> tuple[int, int]:
        """(column, row) of the pixel a label's text is centred on: its point plus its
        offset in points."""
        x, y = self.drawing.ax.transData.transform(label.xy)
        dx, dy = label.xyann
        scale = self.figure.dpi / 72.0
        return round(x + dx * scale), self.canvas.get_width_height()[1] - round(y + dy * scale)

    def _label_sprite(self, label: Any) -> tuple[Pixels, int, int]:
        """A label's sprite, drawn at the middle of the axes (wherever it is now: a
        frame that does not assemble leaves the labels unplaced)."""
        x0, x1, y0, y1 = self.scene.limits
        was = label.xy
        label.xy = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
        sprite = self._sprite(label, self._pixel(label))
        label.xy = was
        return sprite

    def _sprite(self, artist: Any, anchor: tuple[int, int]) -> tuple[Pixels, int, int]:
        """``artist`` drawn alone on a transparent canvas where it is, cropped: (RGBA
        pixels, column and row of the top-left pixel counted from ``anchor``)."""
        renderer = self.canvas.get_renderer()
        renderer.clear()
        visible = artist.get_visible()
        artist.set_visible(True)
        artist.draw(renderer)
        artist.set_visible(visible)
        rgba = np.asarray(renderer.buffer_rgba())
        rows, cols = np.nonzero(rgba[..., 3])
        if rows.size == 0:
            return np.zeros((0, 0, 4), np.uint8), 0, 0
        r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
        return rgba[r0:r1, c0:c1].copy(), int(c0) - anchor[0], int(r0) - anchor[1]

    def frame(self, k: int) -> Pixels:
        """The RGB image of frame ``k``."""
        self.drawing.show(k)
        self.canvas.restore_region(self.background)
        renderer = self.canvas.get_renderer()
        for a in self.changing:
            a.draw(renderer)
        for a in self.moving:
            a.draw(renderer)
        image: Pixels = np.asarray(renderer.buffer_rgba())[..., :3].copy()
        for label, (sprite, dc, dr) in zip(self.labels, self.label_sprites, strict=True):
            if label.get_visible() and sprite.size:
                column, row = self._pixel(label)
                _paste(image, sprite, row + dr, column + dc)
        for key, (sprite, dc, dr) in zip(self.keys, self.key_sprites, strict=True):
            if key.get_visible() and sprite.size:
                _paste(image, sprite, dr, dc)
        return image

    def frames(self, progress: Callable[[int, int], None] | None = None) -> Iterator[Pixels]:
        """The images of every shown frame, in order; ``progress(done, total)`` after each."""
        ks = [int(k) for k in self.scene.shown]
        for done, k in enumerate(ks, 1):
            yield self.frame(k)
            if progress is not None:
                progress(done, len(ks))


def _paste(image: Pixels, sprite: Pixels, r0: int, c0: int) -> None:
    """Blend an RGBA sprite onto an RGB image with its top-left pixel at (r0, c0)."""
    height, width = image.shape[:2]
    h, w = sprite.shape[:2]
    ra, rb = max(r0, 0), min(r0 + h, height)
    ca, cb = max(c0, 0), min(c0 + w, width)
    if ra >= rb or ca >= cb:
        return
    part = sprite[ra - r0 : rb - r0, ca - c0 : cb - c0].astype(np.float32)
    alpha = part[..., 3:4] / 255.0
    under = image[ra:rb, ca:cb].astype(np.float32)
    image[ra:rb, ca:cb] = np.rint(part[..., :3] * alpha + under * (1.0 - alpha)).astype(np.uint8)


def shared_palette(frames: list[Pixels]) -> PILImage.Image:
    """One palette for every frame: the drawing's own colours exactly (white, black, the
    links', the driver's, the groups', the vectors'), then the colours of a sample of
    all frames' pixels (every third row and column of twelve frames spread over the
    cycle: the blends of anti-aliased edges) by octree."""
    from matplotlib.colors import to_rgb
    from PIL import Image

    exact = {tuple(round(255 * c) for c in to_rgb(x)) for x in STYLE_COLOURS}
    step = max(1, len(frames) // 12)
    sample = np.concatenate([f[::3, ::3] for f in frames[::step]], axis=0)
    blends = Image.fromarray(sample).quantize(
        colors=GIF_COLOURS - len(exact), method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE
    )
    used = 3 * (GIF_COLOURS - len(exact))
    table = [v for rgb in sorted(exact) for v in rgb] + list(blends.getpalette() or [])[:used]
    palette = Image.new("P", (1, 1))
    palette.putpalette(table)
    return palette


def _indexed(frames: list[Pixels]) -> list[PILImage.Image]:
    from PIL import Image

    palette = shared_palette(frames)
    return [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]


def _write_gif(frames: list[Pixels], path: str, fps: int) -> None:
    images = _indexed(frames)
    images[0].save(
        path,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=round(1000 / fps),
        loop=0,
        # keep the one palette as it is (each frame repeats it as its own table: that
        # costs 768 bytes a frame, while making it the only table costs a remapping)
        optimize=False,
    )


def _write_html(frames: list[Pixels], path: str, fps: int, title: str) -> None:
    """One page: the frames as PNG data URLs, with play, pause, step, slider and loop."""
    urls = []
    for image in _indexed(frames):
        buf = io.BytesIO()
        image.save(buf, format="PNG", compress_level=1)
        urls.append("data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii"))
    height, width = frames[0].shape[:2]
    page = _PAGE.format(
        title=html.escape(title),
        width=width,
        height=height,
        last=len(urls) - 1,
        count=len(urls),
        interval=round(1000 / fps),
        frames=",\n".join(f'"{u}"' for u in urls),
    )
    with open(path, "w", encoding="utf-8") as f:
        f.write(page)


_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1em; }}
#controls {{ display: flex; gap: 0.4em; align-items: center; margin-top: 0.4em; }}
#controls button {{ min-width: 3em; }}
#slider {{ width: {width}px; max-width: 60vw; }}
</style>
</head>
<body>
<img id="frame" width="{width}" height="{height}" alt="{title}">
<div id="controls">
<button id="play" type="button">play</button>
<button id="pause" type="button">pause</button>
<button id="previous" type="button">&#9664;</button>
<button id="next" type="button">&#9654;</button>
<input id="slider" type="range" min="0" max="{last}" value="0">
<label><input id="loop" type="checkbox" checked> loop</label>
<span id="counter">1 / {count}</span>
</div>
<script>
const frames = [
{frames}
];
let current = 0, timer = null;
const img = document.getElementById("frame");
const slider = document.getElementById("slider");
const counter = document.getElementById("counter");
function show(k) {{
  current = (k + frames.length) % frames.length;
  img.src = frames[current];
  slider.value = current;
  counter.textContent = (current + 1) + " / " + frames.length;
}}
function step() {{
  if (current + 1 >= frames.length && !document.getElementById("loop").checked) {{
    pause(); return;
  }}
  show(current + 1);
}}
function play() {{ if (timer === null) timer = setInterval(step, {interval}); }}
function pause() {{ if (timer !== null) {{ clearInterval(timer); timer = null; }} }}
document.getElementById("play").onclick = play;
document.getElementById("pause").onclick = pause;
document.getElementById("previous").onclick = () => {{ pause(); show(current - 1); }};
document.getElementById("next").onclick = () => {{ pause(); show(current + 1); }};
slider.oninput = () => {{ pause(); show(parseInt(slider.value)); }};
show(0);
</script>
</body>
</html>
"""


def _write_mp4(renderer: FrameRenderer, path: str, fps: int, dpi: int, progress: Any) -> None:
    """Through matplotlib's ffmpeg writer: each frame drawn by matplotlib (labels too)."""
    from matplotlib import animation

    writer = animation.FFMpegWriter(fps=fps)
    ks = [int(k) for k in renderer.scene.shown]
    with writer.saving(renderer.figure, path, dpi):
        for done, k in enumerate(ks, 1):
            renderer.drawing.show(k)
            writer.grab_frame()
            if progress is not None:
                progress(done, len(ks))


def write_animation(
    scene: Scene,
    path: str,
    fps: int = 20,
    dpi: int = 80,
    progress: Callable[[int, int], None] | None = None,
    name: str = "path",
    radians: bool = False,
) -> None:
    """Draw every shown frame of ``scene`` and write the animation to ``path``.

    Parameters
    ----------
    scene : a scene over a cycle (:func:`~mjstruct.plot.drawing.scene_over_cycle`).
    path : ``.gif``, ``.html`` (self-contained, with play controls) or ``.mp4``.
    fps : frames per second.
    dpi : resolution of each frame.
    progress : called as ``progress(done, total)`` after each frame.
    name : what error messages call ``path``.
    radians : the title's driver angles in radians (default: degrees, 0 to 360).

    Raises
    ------
    MechanismError
        an unsupported suffix, an unwritable path, ``.mp4`` without ffmpeg.
    """
    suffix = check_output(path, ANIMATION_SUFFIXES, name=name)
    if fps < 1:
        raise MechanismError(f"fps: must be >= 1, got {fps}")
    if suffix == ".mp4" and not ffmpeg_available():
        raise MechanismError(
            f"{name}: writing .mp4 needs ffmpeg, which is not installed (use .gif or .html)"
        )
    renderer = FrameRenderer(scene, dpi, radians=radians)

    def write(tmp: str) -> None:
        if suffix == ".mp4":
            _write_mp4(renderer, tmp, fps, dpi, progress)
            return
        frames = list(renderer.frames(progress))
        if suffix == ".gif":
            _write_gif(frames, tmp, fps)
        else:
            _write_html(frames, tmp, fps, scene.model.mechanism.name or "mechanism")

    write_atomically(path, write, name=name)
