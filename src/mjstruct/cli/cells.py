"""``mjstruct cells --kmax K [--dof F] [--count]``: synthesis cells and realisable codes.

``--count`` beyond the shipped catalogs enumerates atlases: a job estimated above
:data:`mjstruct.synthesis.cells.ENUMERATION_LIMIT` chains is refused with its estimate
unless ``--large``; a long one shows a progress bar on a terminal.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError
from mjstruct.structure.mobility import link_count
from mjstruct.synthesis.cells import ENUMERATION_LIMIT


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--kmax", type=int, required=True, help="largest number of loops K")
    p.add_argument("--dof", type=int, default=None, help="also the [LA] for F DOF")
    p.add_argument(
        "--count",
        action="store_true",
        help="count non-isomorphic admissible chains per (cell, [MJA], [LA]) (needs --dof)",
    )
    p.add_argument("--sj", action="store_true", help="with --count: also V = 0 rows")
    p.add_argument(
        "--fractionated",
        action="store_true",
        help="with --dof: also chains with a cut vertex (links and MJs of more than K + 1)",
    )
    p.add_argument(
        "--workers", type=int, default=1, help="processes (default 1; at most the cores)"
    )
    p.add_argument(
        "--large",
        action="store_true",
        help=f"allow --kmax above {MAX_KMAX}, and a --count that enumerates more than "
        f"{ENUMERATION_LIMIT} chains beyond the shipped catalogs (a long run)",
    )
    p.add_argument("--json", action="store_true")


#: largest --kmax without --large: 240 cells, 71 183 [MJA] assortments, 0.6 s
MAX_KMAX = 16
#: [MJA] assortments at K = MAX_KMAX, and their growth per loop (measured: 9 570 at
#: K = 12, 27 130 at 14, 71 183 at 16: about 1.6 times per loop)
COUNT_AT_MAX, GROWTH = 71_183, 1.6


def _expected_count(kmax: int) -> str:
    """The [MJA] assortment count expected at ``kmax`` > MAX_KMAX, as text (10^N when
    it is too large to write)."""
    log10 = math.log10(COUNT_AT_MAX) + (kmax - MAX_KMAX) * math.log10(GROWTH)
    return f"{10**log10:.2g}" if log10 < 15 else f"10^{log10:.0f}"


def run(args: argparse.Namespace) -> int:
    from mjstruct.structure.assortments import Assortment
    from mjstruct.structure.codes import full_code
    from mjstruct.synthesis.cells import cells, code_counts, link_assortments

    if args.kmax < 2:
        raise MechanismError(f"--kmax: cells need K >= 2, got {args.kmax}")
    if args.kmax > MAX_KMAX and not args.large:
        raise MechanismError(
            f"--kmax: K <= {args.kmax} gives about {_expected_count(args.kmax)} [MJA] "
            f"assortments ({COUNT_AT_MAX} at K = {MAX_KMAX}, about {GROWTH} times more per "
            f"loop): over the limit of K = {MAX_KMAX}; pass --large to run it"
        )
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
        rows = _counts(args, code_counts)
        for r in rows:
            counts.setdefault((r.K, r.V), []).append(r)
    for c in cs:
        d: dict[str, Any] = {"K": c.K, "V": c.V, "MJA": [list(m) for m in c.MJA]}
        if args.dof is not None:
            d["n"] = link_count(args.dof, c.K)
            d["LA"] = [list(la) for la in link_assortments(c.K, c.V, args.dof, args.fractionated)]
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


def _counts(args: argparse.Namespace, code_counts: Any) -> Any:
    """``code_counts`` for the command: refused with the estimate unless ``--large``,
    with a progress bar on a terminal."""
    from mjstruct.synthesis.parallel import ProgressBar

    bar = ProgressBar.for_cli(f"cells F={args.dof} K<={args.kmax}", args.json)
    try:
        with flag_names(workers="--workers"):
            return code_counts(
                args.dof,
                args.kmax,
                args.fractionated,
                workers=args.workers,
                with_sj=args.sj,
                limit=None if args.large else ENUMERATION_LIMIT,
                progress=bar,
            )
    except MechanismError as exc:
        text = str(exc)
        if text.startswith("limit: "):
            raise MechanismError(
                f"--kmax: {text.removeprefix('limit: ')}; pass --large to run it "
                "(or a smaller --kmax)"
            ) from None
        raise
