"""Animations of a scene over one cycle: GIF, self-contained HTML, MP4 (with ffmpeg).

Owns writing a :class:`~mjstruct.plot.drawing.Scene` frame by frame through
matplotlib's writers: the pillow writer for ``.gif``, the HTML writer with embedded
frames and play controls for ``.html`` (one file, nothing beside it), and ffmpeg for
``.mp4`` only when ffmpeg is installed.  The axes stay fixed over the cycle (the
scene's limits); a frame that does not assemble is drawn as a gap with a note, a
frame at a branch point marks it.  The file appears only when complete.

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

from collections.abc import Callable
from typing import Any

from mjstruct.errors import MechanismError
from mjstruct.plot.drawing import Scene, draw_scene, figure_for
from mjstruct.plot.files import check_output, write_atomically

#: output suffixes an animation can be written to
ANIMATION_SUFFIXES = (".gif", ".html", ".mp4")


def ffmpeg_available() -> bool:
    """Whether matplotlib finds an ffmpeg executable."""
    from matplotlib import animation

    return bool(animation.writers.is_available("ffmpeg"))


def _writer(suffix: str, fps: int, name: str) -> Any:
    from matplotlib import animation

    if suffix == ".gif":
        return animation.PillowWriter(fps=fps)
    if suffix == ".html":
        return animation.HTMLWriter(fps=fps, embed_frames=True, default_mode="loop")
    if not ffmpeg_available():
        raise MechanismError(
            f"{name}: writing .mp4 needs ffmpeg, which is not installed (use .gif or .html)"
        )
    return animation.FFMpegWriter(fps=fps)


def write_animation(
    scene: Scene,
    path: str,
    fps: int = 20,
    dpi: int = 80,
    progress: Callable[[int, int], None] | None = None,
    name: str = "path",
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

    Raises
    ------
    MechanismError
        an unsupported suffix, an unwritable path, ``.mp4`` without ffmpeg.
    """
    import matplotlib.pyplot as plt

    suffix = check_output(path, ANIMATION_SUFFIXES, name=name)
    if fps < 1:
        raise MechanismError(f"fps: must be >= 1, got {fps}")
    writer = _writer(suffix, fps, name)
    fig = figure_for(scene, width=6.0)
    ax = fig.add_subplot()
    frames = [int(k) for k in scene.shown]

    def write(tmp: str) -> None:
        with writer.saving(fig, tmp, dpi):
            for done, k in enumerate(frames, 1):
                # remove the last frame's artists (cheaper than clearing the axes)
                keep = set(map(id, ax.get_children()))
                draw_scene(scene, k, ax=ax)
                writer.grab_frame()
                for a in ax.get_children():
                    if id(a) not in keep:
                        a.remove()
                if ax.get_legend() is not None:
                    ax.get_legend().remove()
                if progress is not None:
                    progress(done, len(frames))

    try:
        write_atomically(path, write, name=name)
    finally:
        plt.close(fig)
