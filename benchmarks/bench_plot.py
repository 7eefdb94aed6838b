"""Speed of the drawings, measured side by side in one run.

* Scene of one cycle (what an animation computes before drawing): plain (positions
  only) against every layer (Assur groups, velocity, acceleration, paths, loads,
  inertia, reactions) on the five-cylinder radial engine with dynamics data.  A scene
  computes only what it shows, so the plain scene should be several times cheaper.
* The whole animation written as a GIF, plain against every layer.
* One drawing written as SVG, and a notebook's ``_repr_svg_`` of a mechanism.
* The animation goal: ``mjstruct animate`` of 72 frames of the radial engine (GIF)
  against one ``mjstruct draw`` of the same mechanism (PNG), both as commands run
  side by side (what a user waits for); goal: at most 2.5 times.  In the same run, the
  72 frames written in one process by the animation writer against the way it drew
  them before (the whole scene drawn again for every frame, and each frame quantised
  on its own by matplotlib's pillow writer).
* The notebook explorer (``mjstruct.explore``) on the six-bar of the user guide (an
  MJ and a slider): one update after the driver's slider moved, and one after a
  joint's slider moved (the mechanism rebuilt, its cycle solved, its singular
  positions found, the picture drawn as PNG), against one drawing of the same
  mechanism written as PNG in the same process; goal: an update under 100 ms.

Run: ``python benchmarks/bench_plot.py [--repeat N] [--frames N] [--explorer]``
(``--explorer``: that part only); prints medians and ratios.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.animation import write_animation
from mjstruct.plot.drawing import draw_scene, figure_for, scene_at, scene_over_cycle, write_drawing
from timing import race

EVERY = ("assur", "velocity", "acceleration", "paths", "loads", "inertia", "reactions")
#: animate may take this many times one draw (72 frames of the radial engine)
GOAL = 2.5
#: an explorer update (driver or joint moved) takes less than this (ms)
EXPLORER_GOAL = 100.0


def redrawn_each_frame(scene, path: str, dpi: int = 80) -> None:
    """The animation as it was drawn before: the whole scene drawn again for every frame
    and every frame quantised on its own (matplotlib's pillow writer)."""
    import matplotlib.pyplot as plt
    from matplotlib import animation

    writer = animation.PillowWriter(fps=20)
    fig = figure_for(scene, width=6.0)
    ax = fig.add_subplot()
    with writer.saving(fig, path, dpi):
        for k in scene.shown:
            ax.clear()
            draw_scene(scene, int(k), ax=ax)
            writer.grab_frame()
    plt.close(fig)


def command_goal(repeat: int) -> None:
    """``mjstruct animate --frames 72`` against ``mjstruct draw``, run as commands."""
    engine = str(example_path("kin-radial-engine-5"))
    tmp = tempfile.mkdtemp()

    def command(*argv: str):
        return lambda: subprocess.run(
            [sys.executable, "-m", "mjstruct", *argv], check=True, capture_output=True
        )

    draw, animate = race(
        [
            command("draw", engine, "-o", os.path.join(tmp, "d.png")),
            command("animate", engine, "--frames", "72", "-o", os.path.join(tmp, "a.gif")),
        ],
        repeat,
    )
    ratio = animate / draw
    verdict = "met" if ratio <= GOAL else "NOT met"
    print("commands (radial engine, defaults; start-up included):")
    print(f"  mjstruct draw -o d.png                 {draw:6.2f} s")
    print(f"  mjstruct animate --frames 72 -o a.gif  {animate:6.2f} s   ratio {ratio:4.2f}x "
          f"(goal <= {GOAL}x: {verdict})")  # fmt: skip
    model = KinematicModel.build(read_mechanism(engine))
    scene = scene_over_cycle(model, 72)
    png, gif = os.path.join(tmp, "d.png"), os.path.join(tmp, "a.gif")
    one, now, before = race(
        [
            lambda: write_drawing(scene_at(model), png),
            lambda: write_animation(scene, gif),
            lambda: redrawn_each_frame(scene, gif),
        ],
        max(1, repeat // 2),
    )
    print("in one process (imports excluded):")
    print(f"  one drawing (PNG)                      {one:6.2f} s")
    print(f"  72 frames (GIF)                        {now:6.2f} s   ratio {now / one:4.1f}x")
    print(f"  72 frames redrawn and quantised each   {before:6.2f} s   "
          f"{before / now:4.1f}x the time of the above")  # fmt: skip


def explorer_goal(repeat: int) -> None:
    """The explorer's updates against one drawing, in one process."""
    from itertools import cycle

    from mjstruct.plot.explorer_view import ExplorerView
    from mjstruct.singular.analysis import singular_analysis

    m = read_mechanism(example_path("six-bar-mj-slider"))
    model = KinematicModel.build(m)
    png = os.path.join(tempfile.mkdtemp(), "d.png")
    view = ExplorerView(m, ["B", "O2"])
    angles = cycle(range(0, 360, 7))
    places = cycle([(2.615, 2.47), (2.7, 2.5), (2.55, 2.4)])

    def driver() -> bytes:
        view.set_driver(next(angles))
        return view.png()

    def joint() -> bytes:
        x, y = next(places)
        assert view.move_joint("B", x, y)
        return view.png()

    n = max(3, 4 * repeat)
    fns = [
        lambda: write_drawing(scene_at(model), png),
        driver,
        joint,
        lambda: singular_analysis(m),
    ]
    wall = race(fns, n)
    cpu = race(fns, n, clock=time.process_time)
    print(
        f"explorer, six-bar of the user guide (median of {n}, wall and CPU time of this process):"
    )
    names = (
        "one drawing (PNG)",
        "update after the driver moved",
        "update after a joint moved",
        "  of which its singular analysis",
    )
    for k, name in enumerate(names):
        ratio = (
            f"   ratio {wall[k] / wall[0]:4.2f}x / {cpu[k] / cpu[0]:4.2f}x" if k in (1, 2) else ""
        )
        print(f"  {name:34s} {wall[k] * 1e3:6.1f} ms / {cpu[k] * 1e3:6.1f} ms{ratio}")
    load = os.getloadavg()[0]
    for clock, times in (("wall", wall), ("CPU", cpu)):
        verdict = "met" if max(times[1], times[2]) * 1e3 < EXPLORER_GOAL else "NOT met"
        print(f"  goal, an update < {EXPLORER_GOAL:.0f} ms ({clock} time): {verdict}", end="")
        print(f" (load average {load:.1f} on {os.cpu_count()} cores)" if clock == "wall" else "")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--frames", type=int, default=360, help="frames of the scene timing")
    ap.add_argument("--explorer", action="store_true", help="only the explorer's updates")
    args = ap.parse_args()
    explorer_goal(args.repeat)
    if args.explorer:
        return
    command_goal(args.repeat)
    m = read_mechanism(example_path("radial-engine-5-dynamics"))
    model = KinematicModel.build(m)
    n = args.frames
    print(f"radial engine (5 cylinders, one MJ of 6 links), scene of {n} frames:")
    plain, every = race(
        [lambda: scene_over_cycle(model, n), lambda: scene_over_cycle(model, n, EVERY)],
        args.repeat,
    )
    print(f"  plain (positions only)      {plain * 1e3:8.1f} ms")
    print(f"  every layer                 {every * 1e3:8.1f} ms   ratio {every / plain:5.1f}x")

    tmp = tempfile.mkdtemp()
    gif = os.path.join(tmp, "a.gif")
    frames = 24
    s_plain = scene_over_cycle(model, frames)
    s_every = scene_over_cycle(model, frames, EVERY)
    print(f"GIF of {frames} frames (dpi 50), drawing and writing only:")
    a, b = race(
        [
            lambda: write_animation(s_plain, gif, dpi=50),
            lambda: write_animation(s_every, gif, dpi=50),
        ],
        max(1, args.repeat // 2),
    )
    print(f"  plain                       {a:8.2f} s  ({a / frames * 1e3:.0f} ms per frame)")
    print(f"  every layer                 {b:8.2f} s  ratio {b / a:5.1f}x")
    full_plain, full_every = race(
        [
            lambda: write_animation(scene_over_cycle(model, frames), gif, dpi=50),
            lambda: write_animation(scene_over_cycle(model, frames, EVERY), gif, dpi=50),
        ],
        max(1, args.repeat // 2),
    )
    print("GIF including the scene computation:")
    print(f"  plain                       {full_plain:8.2f} s")
    print(
        f"  every layer                 {full_every:8.2f} s  ratio {full_every / full_plain:5.1f}x"
    )

    svg = os.path.join(tmp, "d.svg")
    engine = KinematicModel.build(read_mechanism(example_path("kin-radial-engine-5")))
    (draw,) = race([lambda: write_drawing(scene_at(engine, 1.0, ("assur", "velocity")), svg)],
                   args.repeat)  # fmt: skip
    print(f"one drawing (assur, velocity) as SVG: {draw * 1e3:.0f} ms")
    if hasattr(m, "_repr_svg_"):
        (nb,) = race([lambda: m._repr_svg_()], args.repeat)
        print(f"Mechanism._repr_svg_ (notebook):      {nb * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
