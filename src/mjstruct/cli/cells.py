"""``mjstruct cells --kmax K [--dof F] [--count]``: synthesis cells and realisable codes."""

from __future__ import annotations

import argparse
from typing import Any

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError
from mjstruct.structure.mobility import link_count


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--kmax", type=int, required=True, help="largest number of loops K")
    p.add_argument("--dof", type=int, default=None, help="also the [LA] for F DOF")
    p.add_argument(
        "--count",
        action="store_true",
        help="count non-isomorphic admissible chains per (cell, [MJA], [LA]) (needs --dof)",
    )
    p.add_argument("--sj", action="store_true", help="with --count: also V = 0 rows")
    p.add_argument("--fractionated", action="store_true", help="with --count: count them too")
    p.add_argument(
        "--workers", type=int, default=1, help="processes (default 1; at most the cores)"
    )
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from mjstruct.structure.assortments import Assortment
    from mjstruct.structure.codes import full_code
    from mjstruct.synthesis.cells import cells, code_counts, link_assortments

    if args.kmax < 2:
        raise MechanismError(f"--kmax: cells need K >= 2, got {args.kmax}")
    if args.count and args.dof is None:
        raise MechanismError("--count: needs --dof F")
    if args.dof is not None and args.dof < 1:
        raise MechanismError(f"--dof: need F >= 1, got {args.dof}")
    if args.workers < 1:
        raise MechanismError(f"--workers: need at least 1, got {args.workers}")
    cs = cells(args.kmax)
    out: dict[str, Any] = {"kmax": args.kmax, "count": len(cs), "cells": []}
    counts: dict[tuple[int, int], list[Any]] = {}
    if args.count:
        with flag_names(limit="--kmax", workers="--workers"):
            rows = code_counts(
                args.dof, args.kmax, args.fractionated, workers=args.workers, with_sj=args.sj
            )
        for r in rows:
            counts.setdefault((r.K, r.V), []).append(r)
    for c in cs:
        d: dict[str, Any] = {"K": c.K, "V": c.V, "MJA": [list(m) for m in c.MJA]}
        if args.dof is not None:
            d["n"] = link_count(args.dof, c.K)
            d["LA"] = [list(la) for la in link_assortments(c.K, c.V, args.dof)]
        if args.count:
            d["codes"] = [
                {
                    "MJA": list(r.MJA),
                    "LA": list(r.LA),
                    "code_star": full_code(Assortment(LA=r.LA, MJA=r.MJA), r.K),
                    "chains": r.count,
                    "planar": r.planar,
                }
                for r in counts.get((c.K, c.V), [])
            ]
        out["cells"].append(d)
    if args.count and args.sj:
        out["simple_joint"] = [
            {"K": r.K, "LA": list(r.LA), "chains": r.count, "planar": r.planar}
            for (K, V), rs in sorted(counts.items())
            if V == 0
            for r in rs
        ]
    if args.dof is not None:
        out["F"] = args.dof
    if args.json:
        emit_json(out)
        return 0
    lines = [f"{len(cs)} cells (K, V) with 2 <= K <= {args.kmax}, 1 <= V <= 2(K - 1)"]
    for d in out["cells"]:
        mjas = " ".join("[" + "·".join(map(str, m)) + "]" for m in d["MJA"])
        lines.append(f"K = {d['K']}, V = {d['V']}: [MJA] {mjas}")
        if "codes" in d:
            for r in d["codes"]:
                lines.append(
                    f"    {r['code_star']:<24} {r['chains']:>6} chains ({r['planar']} planar)"
                )
        elif "LA" in d:
            las = " ".join("[" + "·".join(map(str, la)) + "]" for la in d["LA"])
            lines.append(f"    n = {d['n']}: [LA] {las}")
    for r in out.get("simple_joint", []):
        lines.append(f"K = {r['K']}, V = 0: [LA] {r['LA']}: {r['chains']} chains")
    emit_text("\n".join(lines))
    return 0
