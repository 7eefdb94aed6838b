"""Speed of the drawings, measured side by side in one run.

* Scene of one cycle (what an animation computes before drawing): plain (positions
  only) against every layer (Assur groups, velocity, acceleration, paths, loads,
  inertia, reactions) on the five-cylinder radial engine with dynamics data.  A scene
  computes only what it shows, so the plain scene should be several times cheaper.
* The whole animation written as a GIF, plain against every layer.
* One drawing written as SVG, and a notebook's ``_repr_svg_`` of a mechanism.

Run: ``python benchmarks/bench_plot.py [--repeat N] [--frames N]``; prints medians and ratios.
"""

from __future__ import annotations

import argparse
import os
import tempfile

import matplotlib

matplotlib.use("Agg")

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.plot.animation import write_animation
from mjstruct.plot.drawing import scene_at, scene_over_cycle, write_drawing
from timing import race

EVERY = ("assur", "velocity", "acceleration", "paths", "loads", "inertia", "reactions")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--frames", type=int, default=360, help="frames of the scene timing")
    args = ap.parse_args()
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
