"""``mjstruct iso FILE_A FILE_B``: exact isomorphism by canonical codes, with the
structural invariants of [MJ structure 2020] ([LA], [MJA], [L], link sets at MJs) side by
side.

References
----------
.. [1] A paper on the system analysis of the structure and mobility of planar
   multi-loop linkage mechanisms with multiple joints (in Russian, with an English
   abstract; authors and exact title not given in the available copy), Izvestiya
   vysshikh uchebnykh zavedenii. Mashinostroenie (Proceedings of Higher Educational
   Institutions. Machine Building), no. 2 (719), 2020. [MJ structure 2020] in
   docs/references.md.
.. [2] I. I. Artobolevsky, Theory of Mechanisms and Machines (in Russian), Moscow:
   Nauka, 1988. [Artobolevsky 1988] in docs/references.md.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from mjstruct.cli.output import emit_json, emit_text

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file_a")
    p.add_argument("file_b")
    p.add_argument(
        "--level",
        choices=("chain", "kinds", "mechanism"),
        default="chain",
        help="chain: links/joints only; kinds: also R/P; mechanism: also frame and drivers",
    )
    p.add_argument("--json", action="store_true")


def _fmt(value: object) -> str:
    if value is None:
        return "none (not planar)"
    if isinstance(value, list) and value and isinstance(value[0], list):
        return " ".join("(" + " ".join(map(str, v)) + ")" for v in value)
    if isinstance(value, list):
        return "[" + " ".join(map(str, value)) + "]"
    return str(value)


LEVEL_TEXT = {
    "chain": "chain (links and joints)",
    "kinds": "kinds (R/P joints too)",
    "mechanism": "mechanism (frame and drivers too)",
}


def _variant(m: Mechanism, kinds: bool, frame: bool, drivers: bool) -> Mechanism:
    """``m`` with only the chosen aspects kept: joint kinds, frame, drivers."""
    from mjstruct.mechanism import Mechanism

    joints = [(j.id, j.links, j.kind if kinds else "R") for j in m.joints]
    return Mechanism.build(
        joints, frame=m.frame if frame else None, drivers=m.drivers if drivers else ()
    )


def differences(a: Mechanism, b: Mechanism) -> list[str]:
    """What makes two mechanisms on isomorphic chains differ: each of ``joint kinds``,
    ``frame`` and ``drivers`` that differs on its own (compared with the bare chains),
    or ``arrangement`` when each agrees alone but not together (the drivers sit
    elsewhere relative to the frame, say); [] when the mechanisms are isomorphic.

    >>> from mjstruct.mechanism import Mechanism
    >>> four = [("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])]
    >>> differences(Mechanism.build(four, 0, ["a"]), Mechanism.build(four, 0, ["b"]))
    ['arrangement']
    """
    from mjstruct.structure.isomorphism import canonical_code

    def same(kinds: bool, frame: bool, drivers: bool) -> bool:
        va, vb = _variant(a, kinds, frame, drivers), _variant(b, kinds, frame, drivers)
        return canonical_code(va, "mechanism") == canonical_code(vb, "mechanism")

    if canonical_code(a, "mechanism") == canonical_code(b, "mechanism"):
        return []
    aspects = {
        "joint kinds": same(True, False, False),
        "frame": same(False, True, False),
        "drivers": same(False, False, True),
    }
    return [k for k, ok in aspects.items() if not ok] or ["arrangement"]


def _frame_text(m: Mechanism) -> str:
    from mjstruct.synthesis.names import inversion_name

    if m.frame is None:
        return "no frame"
    joints = len(m.link_joints[m.frame])
    name = inversion_name(m)
    return f"link {m.frame} with {joints} joints" + (f", a {name}" if name else "")


def _difference_text(what: str, a: Mechanism, b: Mechanism) -> str:
    if what == "frame":
        return f"the frame (A: {_frame_text(a)}; B: {_frame_text(b)})"
    if what == "drivers":
        da, db = ", ".join(a.drivers) or "none", ", ".join(b.drivers) or "none"
        return f"the driven joints sit elsewhere in the chain (A drives {da}; B drives {db})"
    if what == "joint kinds":
        return "the revolute and prismatic joints sit elsewhere in the chain"
    return "how the frame, drivers and joint kinds sit relative to one another"


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.structure.invariants import seed_invariants
    from mjstruct.structure.isomorphism import LEVELS, canonical_code

    a, b = read_mechanism(args.file_a), read_mechanism(args.file_b)
    code = canonical_code
    if "gears" in a.extra or "gears" in b.extra:  # gear pairs coloured by type
        from mjstruct.gears.structure import geared_canonical_code as code
    codes = {lv: (code(a, lv), code(b, lv)) for lv in LEVELS}  # type: ignore[arg-type]
    levels = {lv: ca_ == cb_ for lv, (ca_, cb_) in codes.items()}
    ca, cb = codes[args.level]
    ia, ib = seed_invariants(a), seed_invariants(b)
    agree = ia == ib
    diff = differences(a, b) if levels["chain"] else []
    result = {
        "isomorphic": ca == cb,
        "level": args.level,
        "canonical_a": ca,
        "canonical_b": cb,
        "invariants_a": ia.to_dict(),
        "invariants_b": ib.to_dict(),
        "invariants_agree": agree,
        "levels": levels,
        "differences": diff,
    }
    if args.json:
        emit_json(result)
        return 0
    verdict = "isomorphic" if ca == cb else "not isomorphic"
    lines = [f"{args.file_a}: {ca}", f"{args.file_b}: {cb}", f"{verdict} ({args.level} level)"]
    lines.append("at each level:")
    for lv in LEVELS:
        answer = "isomorphic" if levels[lv] else "NOT isomorphic"
        lines.append(f"  {LEVEL_TEXT[lv]:<35} {answer}")
    if diff:
        lines.append("the chains are isomorphic; the mechanisms differ in:")
        lines += [f"  - {_difference_text(d, a, b)}" for d in diff]
    lines.append("structural invariants (A | B):")
    da, db = ia.to_dict(), ib.to_dict()
    labels = {"LA": "[LA]", "MJA": "[MJA]", "loops": "[L]", "mj_link_sets": "links at MJs"}
    for key, label in labels.items():
        mark = "" if da[key] == db[key] else "   <- differ"
        lines.append(f"  {label:<13} {_fmt(da[key])} | {_fmt(db[key])}{mark}")
    if agree and not levels["chain"]:
        lines.append(
            "the structural invariants agree but the chains are NOT isomorphic: "
            "the invariants are necessary, not sufficient"
        )
    emit_text("\n".join(lines))
    return 0
