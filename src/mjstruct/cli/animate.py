"""``mjstruct animate FILE --frames N -o OUT.gif|html|mp4``: the drawing over one cycle,
with the layers chosen by ``--show``; a progress bar on a terminal (stderr)."""

from __future__ import annotations

import argparse

from mjstruct.cli.draw import (
    add_layer_arguments,
    add_model_arguments,
    add_output_arguments,
    finish,
    layer_options,
    read_model,
)
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_arguments(p)
    p.add_argument("--frames", type=int, default=72, help="frames over one cycle (default 72)")
    add_layer_arguments(p)
    p.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    p.add_argument("--dpi", type=int, default=80, help="resolution of each frame (default 80)")
    add_output_arguments(p, ".gif, .html, or .mp4 (needs ffmpeg)")


def run(args: argparse.Namespace) -> int:
    from mjstruct.plot.animation import ANIMATION_SUFFIXES
    from mjstruct.plot.files import check_output

    suffix = check_output(args.output, ANIMATION_SUFFIXES, name="-o")
    if args.frames < 1:
        raise MechanismError(f"--frames: must be >= 1, got {args.frames}")
    if args.fps < 1:
        raise MechanismError(f"--fps: must be >= 1, got {args.fps}")
    if args.dpi < 10:
        raise MechanismError(f"--dpi: must be >= 10, got {args.dpi}")
    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.plot.animation import ffmpeg_available, write_animation

    if suffix == ".mp4" and not ffmpeg_available():
        raise MechanismError(
            "-o: writing .mp4 needs ffmpeg, which is not installed (use .gif or .html)"
        )
    model = read_model(args)
    layers, paths = layer_options(args, model)
    from mjstruct.plot.drawing import scene_over_cycle
    from mjstruct.synthesis.parallel import ProgressBar

    scene = scene_over_cycle(
        model, args.frames, layers, speed=args.speed, paths=paths, stroke=args.stroke
    )
    bar = ProgressBar.for_cli("animate", json_output=args.json)
    write_animation(scene, args.output, fps=args.fps, dpi=args.dpi, progress=bar, name="-o")
    mo = scene.motion
    gaps = [float(q) for q in mo.q[~mo.valid, 0]]
    warnings = list(mo.warnings) + [e.message() for e in mo.events]
    if gaps:
        warnings.insert(0, f"{len(gaps)} of {args.frames} frames do not assemble (drawn as gaps)")
    info = {
        "frames": args.frames,
        "layers": list(layers),
        "gaps": gaps,
        "branch_points": [
            {"q": e.q, "frame": e.frame, "joint": e.joint, "kind": e.kind} for e in mo.events
        ],
    }
    return finish(args, "animate", info, warnings)
