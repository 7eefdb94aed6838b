"""``mjstruct singular FILE``: input limits, output extremes, change points, clearance zones.

The text report is written for people: angles in degrees within one turn (0 to 360,
4 decimals; the input's and the output's alike, as on the charts), the positions in
that order, and the paper's labels said in words (system (4), formula (3)); the JSON
keeps the contract's numbers (radians, continued from the
reference configuration).

References
----------
.. [1] Singular positions and synthesis of hinged multi-joint mechanisms with
   clearances in their revolute pairs (in Russian; eLibrary document code EDN PBGDPR;
   authors, exact title, journal and year not given in the available copy).
   [Four-bar clearances] in docs/references.md.
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism
    from mjstruct.singular.analysis import SingularAnalysis, SingularPosition
    from mjstruct.singular.classification import SingularClass


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", help="one-DOF mechanism file with geometry (.json or .toml)")
    p.add_argument(
        "--clearance",
        type=float,
        metavar="D",
        help="total radial clearance of the pins (file's length unit): adds the zones",
    )
    p.add_argument("--output", metavar="LINK", help="output link (default: see the contract)")
    p.add_argument(
        "--exact", action="store_true", help="also compute each zone by a feasibility search"
    )
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.tolerances import MAX_CLEARANCE
    from mjstruct.singular.analysis import singular_analysis

    if args.clearance is not None and not (math.isfinite(args.clearance) and args.clearance >= 0):
        raise MechanismError(f"--clearance: must be a finite number >= 0, got {args.clearance}")
    if args.clearance is not None and args.clearance > MAX_CLEARANCE:
        # the zone formulas square (r + D): beyond this the square overflows a double
        raise MechanismError(
            f"--clearance: {args.clearance:g} is too large (at most {MAX_CLEARANCE:g})"
        )
    m = read_mechanism(args.file)
    clearance, kept = args.clearance, None
    if clearance is None:
        clearance = kept = file_clearance(m, MAX_CLEARANCE)
    if args.exact and clearance is None:
        raise MechanismError("--exact: needs --clearance")
    with flag_names(output="--output", clearance="--clearance"):
        r = singular_analysis(m, output=args.output, clearance=clearance, exact=args.exact)
    if args.json:
        emit_json(r.to_dict())
    else:
        text = render(r)
        if kept is not None:
            text += (
                f"\nclearance D = {kept:g} from the file (synthesis.clearance, the task's); "
                "--clearance D overrides it"
            )
        emit_text(text)
    return 0


def file_clearance(m: Mechanism, largest: float) -> float | None:
    """The clearance a ``fourbar-ms`` synthesis kept in the file (its ``synthesis`` key),
    checked as ``--clearance`` is; None where the file has none."""
    entry = m.extra.get("synthesis")
    if not isinstance(entry, dict) or "clearance" not in entry:
        return None
    v = entry["clearance"]
    if isinstance(v, bool) or not isinstance(v, int | float) or not 0 <= v <= largest:
        raise MechanismError(
            f"synthesis.clearance: expected a number from 0 to {largest:g}, got {v!r}"
        )
    return float(v)


#: what each kind of singular position means, for the legend under the table
KIND_MEANINGS = {
    "input_limit": "the input cannot pass (in a four-bar the coupler is in line with the output)",
    "output_extreme": "the output reverses (in a four-bar the input is in line with the coupler)",
    "change_point": "two assembly branches cross (all four centres in line in a four-bar)",
}

#: the change-point conditions of system (4) of [Four-bar clearances], by number
SYSTEM4 = {1: "1 + P1 = P2 + P3", 2: "1 + P2 = P1 + P3", 3: "1 + P3 = P1 + P2"}

DEGREE_DIGITS = 4  # 1e-4 deg: finer than any clearance zone the report gives


def _turn(q: float) -> float:
    """A revolute coordinate (rad) in degrees within one turn, [0, 360).

    >>> _turn(2 * math.pi), _turn(-math.pi / 2), round(_turn(7.33), 4)
    (0.0, 270.0, 59.9781)
    """
    deg = math.degrees(q) % 360.0
    return 0.0 if round(deg, DEGREE_DIGITS) in (0.0, 360.0) else deg


def _deg(v: float) -> str:
    """An angle (rad) in degrees with 4 decimals, round-off shown as 0 (no "-0")."""
    d = math.degrees(v)
    return f"{0.0 if abs(d) < 0.5 * 10**-DEGREE_DIGITS else d:.{DEGREE_DIGITS}f}"


def _span(a: float, b: float, revolute: bool) -> str:
    """An input range [a, b] (a <= b): in degrees from its start within one turn.

    >>> _span(math.radians(346.2), math.radians(431.8), True)
    '346.2000 to 71.8000 deg (through 0)'
    >>> _span(math.pi, 2 * math.pi, True), _span(0.5, 1.25, False)
    ('180.0000 to 360.0000 deg', '0.5 to 1.25')
    """
    if not revolute:
        return f"{a:.6g} to {b:.6g}"
    start = _turn(a)
    end = start + math.degrees(b - a)
    if round(end, DEGREE_DIGITS) <= 360.0:
        return f"{start:.{DEGREE_DIGITS}f} to {end:.{DEGREE_DIGITS}f} deg"
    return f"{start:.{DEGREE_DIGITS}f} to {end - 360.0:.{DEGREE_DIGITS}f} deg (through 0)"


def _q(p: SingularPosition, revolute: bool) -> str:
    return f"{_turn(p.q):.{DEGREE_DIGITS}f}" if revolute else f"{p.q:.6g}"


def _zone_method(method: str, lam: float | None, delta: float | None) -> str:
    if method == "formula-3":
        ld = "" if lam is None or delta is None else f", lambda {lam:.4g}, delta {delta:.4g}"
        return f"four-bar formula (3){ld}"
    return "leading-order estimate" if method == "leading-order" else method


def render(r: SingularAnalysis) -> str:
    """The text report of :func:`mjstruct.singular.analysis.singular_analysis`."""
    unit = "deg" if r.revolute else ""
    lines = [f"input: joint {r.input}    output: link {r.output}"]
    if r.input_range.full_turn:
        lines.append("input range: full turn")
    else:
        parts = "; ".join(_span(a, b, r.revolute) for a, b in r.input_range.intervals)
        lines.append(f"input range: {parts}")
    if r.fourbar is not None:
        f = r.fourbar
        sw = "-" if f.swing is None else f"{_deg(f.swing)} deg"
        tr = "-" if f.time_ratio is None else f"{f.time_ratio:.4f}"
        if f.system4:
            conditions = ", ".join(SYSTEM4.get(k, f"({k})") for k in f.system4)
            lines_ = ", ".join(f"(4.{k})" for k in f.system4)
            s4 = (
                f"change point: {conditions} (system (4) of [Four-bar clearances], "
                f"{'line' if len(f.system4) == 1 else 'lines'} {lines_})"
            )
        else:
            s4 = "no change point (no condition of system (4) of [Four-bar clearances] holds)"
        lines += [
            f"four-bar MS = [{f.MS[0]:.6g} {f.MS[1]:.6g} {f.MS[2]:.6g}] (input, coupler, output "
            f"over the frame): {f.motion}, {'Grashof' if f.grashof else 'non-Grashof'}",
            f"  {s4}",
            f"  output (link {r.fourbar_output}) swing {sw}, time ratio {tr}",
        ]
    order = sorted(r.singular, key=lambda p: _turn(p.q) if r.revolute else p.q)
    lines.append(f"singular positions ({len(r.singular)}):")
    q_head = "q (deg)" if r.revolute else "q"
    lines.append(f"  {'kind':<15} {q_head:>10} {'output (deg)':>13}  {'class':<9} joints in line")
    for p in order:
        lines.append(
            f"  {p.kind:<15} {_q(p, r.revolute):>10} {_q_value(p.output_angle, True):>13}  "
            f"{_notation(p.classification):<9} {' '.join(p.collinear) or '-'}"
        )
        for z in p.zone or ():
            psi = "-" if z.psi is None else _deg(z.psi)
            ex = "" if z.psi_exact is None else f"; exact search {_deg(z.psi_exact)} deg"
            lines.append(
                f"      zone: links {z.pair[0]} and {z.pair[1]} in line, link {z.link} turns "
                f"{psi} deg ({_zone_method(z.method, z.lam, z.delta)}{ex})"
            )
        if p.zone is not None and not p.zone:
            c = p.classification
            theta = (
                ""
                if c is None or c.theta is None
                else f"; theta {_deg(c.theta)} deg (leading-order estimate, the link that "
                "turns most)"
            )
            lines.append(f"      zone: none (no two moving links in line){theta}")
    kinds = [k for k in KIND_MEANINGS if any(p.kind == k for p in r.singular)]
    if kinds:
        lines.append("  where")
        lines += [f"    {k}: {KIND_MEANINGS[k]}" for k in kinds]
    for a in r.fold_arcs:
        what = (
            "input locked"
            if a.kind == "input_limit"
            else f"output dwells at {_q_value(a.output_angle or 0.0, True)} deg"
        )
        span = (
            f"q = {_q_value(a.q_from, r.revolute)} {unit}".rstrip()
            if a.q_to == a.q_from
            else f"q from {_span(a.q_from, a.q_to, r.revolute)}"
        )
        c = a.classification
        cls = "" if c is None else f": {c.notation}"
        if c is not None and c.theta is not None:
            cls += f", zone {_deg(c.theta)} deg"
        lines.append(f"fold arc: {what} for {span}, {' '.join(a.joints) or '-'} coinciding{cls}")
    lines += _class_legend(r)
    if r.clearance is not None:
        lines.append(
            f"zones: clearance D = {r.clearance:g} (total radial, split evenly over the pins); "
            "how far the longer link of a pair in line can turn about its pivot while the "
            "chain still closes"
        )
        if any(z.method == "formula-3" for p in r.singular for z in p.zone or ()):
            lines.append(
                "  four-bar formula (3) of [Four-bar clearances]: exact for a four-bar; "
                "lambda = shorter over longer link of the pair, delta = D over the longer link"
            )
        if any(z.method == "leading-order" for p in r.singular for z in p.zone or ()):
            lines.append(
                "  leading-order estimate: the small-clearance limit, for any linkage "
                "(its relative error is about D over the link length)"
            )
    lines += [f"warning: {w}" for w in r.warnings]
    return "\n".join(lines)


def _notation(c: SingularClass | None) -> str:
    return "-" if c is None else c.notation


def _class_legend(r: SingularAnalysis) -> list[str]:
    """What the classes of the report mean: one line per type present."""
    from mjstruct.singular.classification import TYPES

    found = [p.classification for p in r.singular] + [a.classification for a in r.fold_arcs]
    types = sorted({c.type for c in found if c is not None}, key=list(TYPES).index)
    if not types:
        return []
    out = [
        "classes of [Four-bar clearances]: type/trap//mark, mark П useful (built for it), "
        "В harmful (a trap unless used)"
    ]
    for t in types:
        row = TYPES[t]
        out.append(f"    {t}/{row.trap}: {row.trap_name} (W1 = {row.W1}, W2 = {row.W2})")
    if r.clearance is not None:
        out.append("    zone angle theta of a position: its widest zone above")
    return out


def _q_value(q: float, revolute: bool) -> str:
    return f"{_turn(q):.{DEGREE_DIGITS}f}" if revolute else f"{q:.6g}"
