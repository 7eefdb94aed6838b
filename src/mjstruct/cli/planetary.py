"""``mjstruct planetary --ratio I``: tooth numbers of the 2AA planetary train."""

from __future__ import annotations

import argparse
from typing import Any

from mjstruct.cli.output import emit_json, emit_text, flag_names

_FLAGS = {
    "ratio": "--ratio",
    "satellites": "--satellites",
    "t1": "--t1",
    "t2": "--t2",
    "y": "--y",
    "ratio_tolerance": "--ratio-tolerance",
    "coaxial_tolerance": "--coaxial-tolerance",
    "z_min": "--z-min",
    "z_max": "--z-max",
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--ratio", type=float, required=True, help="required ratio i (gear 1 to H)")
    p.add_argument("--satellites", type=int, default=3, help="satellite sets k (default 3)")
    p.add_argument("--t1", type=float, default=1.0, help="meshing-angle factor of mesh 2-3")
    p.add_argument("--t2", type=float, default=1.0, help="meshing-angle factor of mesh 3-4")
    p.add_argument("--y", type=float, default=1.0, help="Z3/Z2 (default 1)")
    p.add_argument("--ratio-tolerance", type=float, default=0.01, help="relative (0.01)")
    p.add_argument("--coaxial-tolerance", type=float, default=0.01, help="on t2 (0.01)")
    p.add_argument("--z-min", type=int, default=18, help="fewest teeth of any gear (18)")
    p.add_argument("--z-max", type=int, default=300, help="most teeth of any gear (300)")
    p.add_argument("--limit", type=int, default=20, help="sets printed, best first (20)")
    p.add_argument(
        "-o", "--output", help="write the set chosen by --set as a mechanism file (.json)"
    )
    p.add_argument("--set", type=int, default=1, help="with -o: which set, best first (1)")
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from mjstruct.errors import MechanismError
    from mjstruct.gears.planetary import planetary_synthesis

    if args.limit < 0:
        raise MechanismError(f"--limit: must be >= 0, got {args.limit}")
    with flag_names(**_FLAGS):
        r = planetary_synthesis(
            args.ratio,
            args.satellites,
            t1=args.t1,
            t2=args.t2,
            y=args.y,
            ratio_tolerance=args.ratio_tolerance,
            coaxial_tolerance=args.coaxial_tolerance,
            z_min=args.z_min,
            z_max=args.z_max,
        )
    shown = r.sets[: args.limit]
    written = None
    if args.output is not None:
        written = _write(args, r)
    if args.json:
        out: dict[str, Any] = {
            "scheme": "2AA",
            "ratio": r.ratio,
            "satellites": r.satellites,
            "t1": r.t1,
            "t2": r.t2,
            "y": r.y,
            "ratio_tolerance": r.ratio_tolerance,
            "coaxial_tolerance": r.coaxial_tolerance,
            "z_min": r.z_min,
            "z_max": r.z_max,
            "range": r.range.as_dict(),
            "count": r.count,
            "sets": [s.as_dict() for s in shown],
        }
        if written is not None:
            out["output"] = written
        emit_json(out)
        return 0
    g = r.range
    lines = [
        f"2AA planetary train: ratio {r.ratio:g} (±{100 * r.ratio_tolerance:g} %), "
        f"k = {r.satellites}, t1 = {r.t1:g}, t2 = {r.t2:g}, y = {r.y:g}",
        f"admissible ratios {g.lower:.6g} < i < {g.upper:.6g}: (7) lower, (9) "
        f"{g.upper_2:.6g}, (11) " + ("no limit" if g.upper_3 is None else f"{g.upper_3:.6g}"),
        f"{r.count} tooth-number sets with {r.z_min} <= Z <= {r.z_max}"
        + (f", the best {len(shown)} shown" if len(shown) < r.count else ""),
    ]
    if not r.count:
        lines.append("none: widen --z-max, --ratio-tolerance or --coaxial-tolerance")
    if shown:
        lines.append(
            f"{'Z1':>4} {'Z2':>4} {'Z3':>4} {'Z4':>4} {'ratio':>9} {'error %':>8} "
            f"{'t2 exact':>9} {'(Z1+Z4)/k':>9} {'gap 2':>7} {'gap 3':>7}"
        )
    for s in shown:
        lines.append(
            f"{s.z1:>4} {s.z2:>4} {s.z3:>4} {s.z4:>4} {s.ratio:>9.5f} "
            f"{100 * s.ratio_error:>8.3f} {s.t2_exact:>9.5f} {s.assembly_number:>9} "
            f"{s.neighbour_margin_2:>7.2f} {s.neighbour_margin_3:>7.2f}"
        )
    if written is not None:
        lines.append(f"wrote {written} (set {args.set} as a mechanism file)")
    emit_text("\n".join(lines))
    return 0


def _write(args: argparse.Namespace, r: Any) -> str:
    """The chosen set as a mechanism file at ``-o`` (JSON)."""
    import json

    from mjstruct.errors import MechanismError
    from mjstruct.gears.planetary import two_aa_mechanism
    from mjstruct.output_files import write_text

    if not str(args.output).endswith(".json"):
        raise MechanismError(f"-o: a mechanism file ends in .json, got {args.output}")
    if not 1 <= args.set <= r.count:
        raise MechanismError(f"--set: must be in 1..{r.count} (the sets found), got {args.set}")
    data = two_aa_mechanism(r.sets[args.set - 1], r.satellites, r.t1)
    write_text(args.output, json.dumps(data, indent=1) + "\n", name="-o")
    return str(args.output)
