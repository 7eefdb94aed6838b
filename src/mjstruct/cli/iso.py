"""``mjstruct iso FILE_A FILE_B``: exact isomorphism by canonical codes."""

from __future__ import annotations

import argparse

from mjstruct.cli.output import emit_json, emit_text


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


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.structure.isomorphism import canonical_code

    a, b = read_mechanism(args.file_a), read_mechanism(args.file_b)
    ca, cb = canonical_code(a, args.level), canonical_code(b, args.level)
    result = {"isomorphic": ca == cb, "level": args.level, "canonical_a": ca, "canonical_b": cb}
    if args.json:
        emit_json(result)
    else:
        verdict = "isomorphic" if ca == cb else "not isomorphic"
        emit_text(f"{args.file_a}: {ca}\n{args.file_b}: {cb}\n{verdict} ({args.level} level)")
    return 0
