"""``mjstruct animate FILE --frames N -o OUT.gif|html|mp4``: the drawing over one cycle,
with the layers chosen by ``--show``; a progress bar on a terminal (stderr)."""

from __future__ import annotations

import argparse

from mjstruct.cli.draw import (
    add_angle_argument,
    add_layer_arguments,
    add_model_arguments,
    add_output_arguments,
    finish,
    layer_options,
    layer_words,
    read_model,
)
from mjstruct.cli.plot import check_frames_memory
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_arguments(p)
    p.add_argument("--frames", type=int, default=72, help="frames over one cycle (default 72)")
    add_layer_arguments(p)
    add_angle_argument(p)
    p.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    p.add_argument("--dpi", type=int, default=80, help="resolution of each frame (default 80)")
    add_output_arguments(p, ".gif, .html, or .mp4 (needs ffmpeg)")
    p.add_argument(
        "--long",
        action="store_true",
        help=f"allow more than {MAX_FRAMES} frames",
    )
    p.add_argument(
        "--max-memory",
        type=int,
        metavar="BYTES",
        help="memory limit of the estimate (default: MJSTRUCT_MAX_MEMORY_BYTES or 2 GiB)",
    )


#: frames an animation may have without --long (3 minutes at the default 20 fps)
MAX_FRAMES = 3600
#: the animation's figure: 6 inches wide, at most 2 × 6 + 0.6 inches high
#: (:func:`mjstruct.plot.drawing.figure_for`); the .gif and .html writers keep one RGB
#: image per frame and its palette indices (4 bytes a pixel; .mp4 streams to ffmpeg)
FRAME_INCHES = (6.0, 12.6)


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
    if args.frames > MAX_FRAMES and not args.long:
        raise MechanismError(
            f"--frames: {args.frames} frames ({args.frames / args.fps:.3g} s at {args.fps} "
            f"fps) are more than an animation needs (at most {MAX_FRAMES}); pass --long "
            "to allow more"
        )
    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.plot.animation import ffmpeg_available, write_animation

    if suffix == ".mp4" and not ffmpeg_available():
        raise MechanismError(
            "-o: writing .mp4 needs ffmpeg, which is not installed (use .gif or .html)"
        )
    model = read_model(args)
    width, height = (round(inches * args.dpi) for inches in FRAME_INCHES)
    image = 0 if suffix == ".mp4" else 4 * width * height
    check_frames_memory(model, args.frames, args.max_memory, frame_bytes=image)
    layers, paths = layer_options(args, model)
    from mjstruct.plot.drawing import scene_over_cycle
    from mjstruct.synthesis.parallel import ProgressBar

    scene = scene_over_cycle(
        model, args.frames, layers, speed=args.speed, paths=paths, stroke=args.stroke
    )
    bar = ProgressBar.for_cli("animate", json_output=args.json)
    write_animation(
        scene,
        args.output,
        fps=args.fps,
        dpi=args.dpi,
        progress=bar,
        name="-o",
        radians=args.radians,
    )
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
    seconds = args.frames / args.fps
    what = f"{args.frames} frames, {seconds:.3g} s at {args.fps} fps{layer_words(layers)}"
    if gaps:
        what += f"; {len(gaps)} frames do not assemble"
    return finish(args, "animate", info, warnings, what)
