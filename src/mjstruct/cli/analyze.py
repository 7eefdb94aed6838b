"""``mjstruct analyze FILE | --code CODE``: the structural report."""

from __future__ import annotations

import argparse

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", nargs="?", help="mechanism file (.json or .toml)")
    p.add_argument("--code", help='structural code instead of a file, e.g. "[8110]/[3·0·0]"')
    p.add_argument("--dof", type=int, help="with --code: the intended DOF F (fixes K)")
    p.add_argument("--drivers", type=int, help="with --code: number of drivers N (default F)")
    p.add_argument(
        "--lambda", dest="lam", type=int, default=3, help="motion-space dimension (default 3)"
    )
    p.add_argument("--no-loops", action="store_true", help="skip [L] (the embedding search)")
    p.add_argument("--json", action="store_true", help="print the contract's JSON object")


def run(args: argparse.Namespace) -> int:
    from mjstruct.report import code_report, structural_report
    from mjstruct.report_text import render

    if args.lam < 2:
        raise MechanismError(f"--lambda: must be >= 2, got {args.lam}")
    if (args.file is None) == (args.code is None):
        raise MechanismError("give either a mechanism FILE or --code CODE")
    if args.code is not None:
        with flag_names(code="--code", dof="--dof", N="--drivers", lam="--lambda"):
            r = code_report(args.code, dof=args.dof, N=args.drivers, lam=args.lam)
    else:
        if args.dof is not None or args.drivers is not None:
            raise MechanismError("--dof and --drivers go with --code; a file has its own")
        from mjstruct.io import read_mechanism

        r = structural_report(
            read_mechanism(args.file), lam=args.lam, with_loops=not args.no_loops
        )
    if args.json:
        emit_json(r.to_dict())
    else:
        emit_text(render(r))
    return 0
