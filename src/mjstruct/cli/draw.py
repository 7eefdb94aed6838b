"""``mjstruct draw FILE [--q Q] [--show LAYERS] -o OUT.svg|png|pdf``: the mechanism drawn
at one configuration, with optional layers (Assur groups, velocity and acceleration
vectors, paths).  Also the arguments and checks that ``animate`` and ``plot`` share.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING, Any

from mjstruct.cli.output import driver_list
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.kinematics.model import KinematicModel


def add_model_arguments(p: argparse.ArgumentParser) -> None:
    """FILE, --drivers, --speed, --stroke: what every drawing command reads."""
    p.add_argument("file", help="mechanism file with geometry (.json or .toml)")
    p.add_argument("--drivers", help="generalised coordinates J1,J2 (default: the file's)")
    p.add_argument("--speed", type=float, default=1.0, help="constant driver speed W (default 1)")
    p.add_argument(
        "--stroke", type=float, default=1.0, help="sweep of a prismatic driver (default 1)"
    )


def add_layer_arguments(p: argparse.ArgumentParser) -> None:
    from mjstruct.plot.layers import LAYERS

    names = ", ".join(LAYERS)
    p.add_argument("--show", default="", help=f"layers, comma-separated: {names}")
    p.add_argument(
        "--paths",
        help="joints or points whose paths the 'paths' layer draws "
        "(default: the file's points, else the moving joints)",
    )


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_model_arguments(p)
    p.add_argument(
        "--q",
        help="driver value(s) Q1,Q2 to draw at (default: the reference configuration); "
        "an angle in degrees as 45deg, in radians as 0.8rad or a bare 0.8 (radians, as "
        "the JSON); a slide in the file's length unit",
    )
    add_layer_arguments(p)
    add_angle_argument(p)
    add_output_arguments(p, ".svg, .png, .pdf, or .dxf (CAD outlines; the cad extra)")
    p.add_argument("--dpi", type=int, default=120, help="resolution of a .png (default 120)")


def add_angle_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--radians",
        action="store_true",
        help="driver angles in radians (default: degrees, the crank angle from 0 to 360)",
    )


def add_output_arguments(p: argparse.ArgumentParser, formats: str) -> None:
    p.add_argument("-o", "--output", required=True, help=f"output file: {formats}")
    p.add_argument("--json", action="store_true", help="print what was written as one JSON object")


def finish(
    args: argparse.Namespace,
    command: str,
    info: dict[str, Any],
    warnings: list[str],
    what: str,
) -> int:
    """Print what was written: one JSON object (``--json``), else one line on stdout,
    ``wrote OUT (WHAT)``, and the warnings on stderr."""
    if args.json:
        from mjstruct.cli.output import emit_json

        emit_json({"output": args.output, **info, "warnings": warnings})
    else:
        from mjstruct.cli.output import emit_error, emit_text

        # one line: names from the file cannot break it into several
        emit_text(f"wrote {args.output} ({what})".replace("\n", " "))
        for w in warnings:  # a warning names joints and links of the file: sanitised
            emit_error(f"mjstruct {command}: warning: {w}")
    return 0


def layer_words(layers: Any) -> str:
    """``", layers a, b"`` for a summary line (nothing without layers)."""
    return f", layers {', '.join(layers)}" if layers else ""


def read_model(args: argparse.Namespace) -> KinematicModel:
    """The kinematic model of FILE with --drivers; checks --speed and --stroke."""
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.model import KinematicModel

    if not args.speed == args.speed or args.speed in (0, float("inf"), float("-inf")):
        raise MechanismError("--speed: must be a finite nonzero number")
    if not 0 < args.stroke < float("inf"):
        raise MechanismError(f"--stroke: must be a positive number, got {args.stroke}")
    m = read_mechanism(args.file)
    drivers = driver_list(args.drivers, m)
    if not (drivers or m.drivers):
        raise MechanismError("--drivers: the file names no drivers; give --drivers J1,J2")
    return KinematicModel.build(m, drivers)


def layer_options(args: argparse.Namespace, model: KinematicModel) -> tuple[Any, Any]:
    """(layers, path ids) from --show and --paths, checked with the flags' names."""
    from mjstruct.plot.layers import parse_layers

    layers = parse_layers(args.show, name="--show")
    paths = None
    if args.paths is not None:
        paths = [x.strip() for x in args.paths.split(",") if x.strip()]
        geom = model.geometry
        for pid in paths:
            if pid not in geom.points and pid not in geom.centres:
                raise MechanismError(f"--paths: {pid!r} is neither a joint nor a point")
        if "paths" not in layers:
            layers = (*layers, "paths")
    return layers, paths


#: what ``--q`` may end with: the unit of a revolute driver's angle
ANGLE_SUFFIXES = {"deg": 1.0, "°": 1.0, "rad": 0.0}


def driver_values(text: str, model: KinematicModel, warnings: list[str]) -> list[float]:
    """``--q Q1,Q2`` in the model's units (radians, lengths).

    A revolute driver's value may carry its unit, ``45deg`` (or ``45°``) or ``0.8rad``;
    a bare number is radians, as it always was (a bare value beyond a full turn, more
    likely meant in degrees, adds a warning saying so).  A slide is in the file's
    length unit and takes no suffix.

    >>> from mjstruct.io import read_mechanism
    >>> from mjstruct.catalog_files import example_path
    >>> from mjstruct.kinematics.model import KinematicModel
    >>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
    >>> [round(v, 6) for v in driver_values("90deg", model, [])]
    [1.570796]
    """
    parts = text.split(",")
    if len(parts) != len(model.drivers):
        raise MechanismError(
            f"--q: expected {len(model.drivers)} finite value(s), one per driver "
            f"({', '.join(model.drivers)})"
        )
    values: list[float] = []
    for part, driver in zip(parts, model.drivers, strict=True):
        word = part.strip().lower()
        unit = next((u for u in ANGLE_SUFFIXES if word.endswith(u)), None)
        number = word[: len(word) - len(unit)].strip() if unit else word
        try:
            v = float(number)
        except ValueError:
            raise MechanismError(
                f"--q: expected numbers Q1,Q2 (angles may end in deg or rad), got {text!r}"
            ) from None
        if not (v == v and abs(v) < 1e300):
            raise MechanismError(
                f"--q: expected {len(model.drivers)} finite value(s), one per driver "
                f"({', '.join(model.drivers)})"
            )
        revolute = model.mechanism.joint(driver).kind == "R"
        if unit is not None and not revolute:
            raise MechanismError(
                f"--q: driver {driver} is a slide, in the file's length unit; "
                f"{unit!r} is for angles"
            )
        if unit is not None and ANGLE_SUFFIXES[unit]:
            v = math.radians(v)
        elif unit is None and revolute and abs(v) > 2 * math.pi:
            warnings.append(
                f"--q {number} for {driver} is taken as radians (a number without a unit "
                f"is; {math.degrees(v) % 360:.1f}° after whole turns); write {number}deg "
                "for degrees"
            )
        values.append(v)
    return values


def run(args: argparse.Namespace) -> int:
    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output

    suffix = check_output(args.output, (*FIGURE_SUFFIXES, ".dxf"), name="-o")
    if suffix == ".dxf":
        return _cad(args)
    if args.dpi < 10:
        raise MechanismError(f"--dpi: must be >= 10, got {args.dpi}")
    from mjstruct.io import read_mechanism

    m = read_mechanism(args.file)
    if any(j.at is None for j in m.joints):
        return _structural(args, m)
    model = read_model(args)
    layers, paths = layer_options(args, model)
    notes: list[str] = []
    q = None if args.q is None else driver_values(args.q, model, notes)

    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.plot.drawing import scene_at, write_drawing
    from mjstruct.plot.scheme import q_text

    scene = scene_at(model, q, layers, speed=args.speed, paths=paths, stroke=args.stroke)
    write_drawing(scene, args.output, dpi=args.dpi, name="-o", radians=args.radians)
    warnings = notes + list(scene.motion.warnings)
    ok = bool(scene.motion.valid[-1])
    if not ok:
        values = ", ".join(f"{v:.9g}" for v in scene.motion.q[-1])
        warnings.append(
            f"the mechanism does not assemble at q = {values} (only the frame is drawn)"
        )
    info = {"layers": list(layers), "q": [float(v) for v in scene.motion.q[-1]], "assembles": ok}
    name = model.mechanism.name or "mechanism"
    at = q_text(scene, int(scene.shown[-1]), args.radians)
    what = f"{name} at q = {at}{layer_words(layers)}"
    return finish(args, "draw", info, warnings, what)


def _cad(args: argparse.Namespace) -> int:
    """``-o OUT.dxf``: the mechanism at the configuration as DXF (the ``cad`` extra)."""
    from mjstruct.plot.dxf import check_dxf

    check_dxf("-o")  # before anything is computed
    for flag, value in (("--show", args.show or None), ("--paths", args.paths)):
        if value is not None:
            raise MechanismError(f"{flag}: a .dxf holds the links' outlines only, no layers")
    model = read_model(args)
    notes: list[str] = []
    q = None if args.q is None else driver_values(args.q, model, notes)
    from mjstruct.plot.dxf import write_dxf
    from mjstruct.plot.scene import scene_at
    from mjstruct.plot.scheme import q_text

    scene = scene_at(model, q, stroke=args.stroke)
    write_dxf(scene, args.output, name="-o")
    links = len([x for x in model.mechanism.links if x != model.frame])
    at = q_text(scene, int(scene.shown[-1]), args.radians)
    name = model.mechanism.name or "mechanism"
    info = {"layers": [], "q": [float(v) for v in scene.motion.q[-1]], "assembles": True}
    what = f"DXF of {name} at q = {at}: {links} link layers and the frame"
    return finish(args, "draw", info, notes + list(scene.motion.warnings), what)


def _structural(args: argparse.Namespace, m: Any) -> int:
    """A file without joint centres: its chain drawn as an atlas panel (no layers, no q)."""
    given = [
        flag
        for flag, v in (("--q", args.q), ("--show", args.show or None), ("--paths", args.paths))
        if v is not None
    ]
    if given:
        raise MechanismError(
            f"{given[0]}: needs joint centres ('at') in the file; without them only the "
            "structural scheme is drawn"
        )
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mjstruct.plot.atlas_sheet import chain_layout, draw_chain
    from mjstruct.plot.files import write_atomically

    fig = plt.figure(figsize=(5, 5))
    try:
        lay = chain_layout(m)
        note = "structural scheme" if lay.planar else "structural scheme; not planar"
        draw_chain(fig.add_subplot(), m, lay, caption=f"{m.name or 'chain'}\n({note})")
        write_atomically(args.output, lambda tmp: fig.savefig(tmp, dpi=args.dpi), name="-o")
    finally:
        plt.close(fig)
    what = f"structural scheme of {m.name or 'chain'}"
    return finish(args, "draw", {"layers": [], "q": None, "assembles": None}, [], what)
