"""``mjstruct analyze FILE | --code CODE``: the structural report."""

from __future__ import annotations

import argparse
from typing import Any

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
    names: tuple[str | None, str | None] = (None, None)
    gears: dict[str, Any] | None = None
    if args.code is not None:
        with flag_names(code="--code", dof="--dof", N="--drivers", lam="--lambda"):
            r = code_report(args.code, dof=args.dof, N=args.drivers, lam=args.lam)
    else:
        if args.dof is not None or args.drivers is not None:
            raise MechanismError("--dof and --drivers go with --code; a file has its own")
        from mjstruct.io import read_mechanism
        from mjstruct.synthesis.names import familiar_name, inversion_name

        m = read_mechanism(args.file)
        if "gears" in m.extra:  # the structural numbers are the equivalent chain's
            from mjstruct.gears.structure import equivalent_chain, geared_report

            gears = geared_report(m)
            m = equivalent_chain(m)
        r = structural_report(m, lam=args.lam, with_loops=not args.no_loops)
        names = (familiar_name(m), inversion_name(m))
    if args.json:
        out = r.to_dict()
        out["inversion_name"] = names[1]
        if gears is not None:
            out["gears"] = gears
        emit_json(out)
    else:
        text = _with_names(render(r), *names)
        emit_text(text if gears is None else text + "\n" + _gears_text(gears))
    return 0


def _gears_text(g: dict[str, Any]) -> str:
    """The geared linkage's lines after the report (which counts lower pairs only)."""
    e = g["equivalent"]
    by_rank = (
        "no geometry for the rank"
        if g["F_rank"] is None
        else f"by rank at the reference: F = {g['F_rank']}, rc = {g['rc']}"
    )
    pairs = ", ".join(
        f"{p['id']} ({p['links'][0]}–{p['links'][1]} {p['type']}"
        + (f", carrier {p['carrier']})" if p["carrier"] else ")")
        for p in g["pairs"]
    )
    return "\n".join(
        [
            "Gear pairs (the report above is that of the equivalent lower-pair chain):",
            f"• p4 = {g['p4']}, p5 = {g['p5']}: F = 3(n − 1) − 2·p5 − p4 = {g['F']}; {by_rank}",
            f"• fundamental circuits (gear pair, transfer vertex): {pairs or 'none'}",
            f"• equivalent lower-pair chain (each mesh a binary link): n = {e['n']}, "
            f"[LA] = {e['LA']}, [MJA] = {e['MJA']}, K = {e['K']}, F = {e['F']}, "
            f"code {e['code']}",
        ]
    )


def _with_names(text: str, chain: str | None, inversion: str | None) -> str:
    """The report with a bullet for the familiar names, after the last bullet."""
    from mjstruct.synthesis.names import inversion_text

    if chain is None:
        return text
    bullet = f"• familiar name of the chain: {chain}"
    if inversion is not None:
        bullet += f"; with this frame: {inversion_text(inversion)}"
    lines = text.split("\n")
    last = max(k for k, line in enumerate(lines) if line.startswith("• "))
    return "\n".join([*lines[: last + 1], bullet, *lines[last + 1 :]])
