"""``mjstruct atlas --dof F --links n [--mj] [--fractionated]``: all non-isomorphic
admissible chains; ``--assur``: Assur groups instead; ``--gears``: one-DOF epicyclic gear
trains (rotation and displacement graphs)."""

from __future__ import annotations

import argparse
from collections import Counter
from typing import Any

from mjstruct.cli.output import emit_json, emit_text, flag_names
from mjstruct.errors import MechanismError
from mjstruct.synthesis.job_size import CHAIN_LIMIT


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dof", type=int, default=1, help="degrees of freedom F (default 1)")
    p.add_argument("--links", type=int, required=True, help="number of links n")
    p.add_argument("--mj", action="store_true", help="also chains with multiple joints")
    p.add_argument("--fractionated", action="store_true", help="also chains with a cut vertex")
    p.add_argument("--assur", action="store_true", help="Assur groups with n links instead")
    p.add_argument(
        "--gears", action="store_true", help="one-DOF epicyclic gear trains with n links instead"
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="processes to use (default 1; at most the number of cores)",
    )
    p.add_argument(
        "--large",
        action="store_true",
        help=f"enumerate even when more than {CHAIN_LIMIT} results are expected",
    )
    p.add_argument(
        "--scheduler", default=None, help="Dask scheduler address (optional dask extra)"
    )
    p.add_argument("--list", action="store_true", help="text output: one line per chain")
    p.add_argument("--json", action="store_true")
    p.add_argument(
        "--draw", metavar="OUT", help="also draw the chains on a sheet (.pdf pages, .svg, .png)"
    )


def _ids(chains: list[Any], F: int, n: int) -> dict[str, str]:
    """Catalog ids of the chains, when (F, n) is shipped."""
    from mjstruct.synthesis.catalog import read_catalog

    return {r["canonical"]: r["id"] for r in read_catalog(F, n)}


def run(args: argparse.Namespace) -> int:
    from mjstruct.synthesis.parallel import ProgressBar

    if args.links < 1:
        raise MechanismError(f"--links: need at least one link, got {args.links}")
    if args.workers < 1:
        raise MechanismError(f"--workers: need at least 1, got {args.workers}")
    if args.gears:
        _check_gear_flags(args)
    if args.draw is not None:
        _check_sheet(args)
    if args.assur:
        return _run_assur(args)
    if args.gears:
        return _run_gears(args)
    if args.dof < 1:
        raise MechanismError(f"--dof: need F >= 1, got {args.dof}")
    from mjstruct.synthesis.names import chain_inversions, familiar_names

    bar = ProgressBar.for_cli(f"atlas F={args.dof} n={args.links}", args.json)
    a = _run_atlas(args, bar)
    # one row per chain only where the output shows them (an atlas holds hundreds of
    # thousands: the summary alone needs none of their dictionaries)
    rows = args.json or args.list
    names = familiar_names() if rows else {}
    ids = _ids(a.chains, args.dof, args.links) if rows or args.draw is not None else {}
    if args.draw is not None:
        _draw_sheet(args, a.chains, ids)
    chains = []
    for c in a.chains if rows else ():
        d: dict[str, Any] = {"id": ids.get(c.canonical), "name": names.get(c.canonical)}
        d.update(c.to_dict())
        d["cell"] = [c.K, c.V]
        # the six-bars' named inversions, each with its frame links (indices)
        inversions = chain_inversions(c.mechanism()) if d["name"] else {}
        d["inversions"] = [
            {"name": k, "frames": sorted(int(x) for x in v)} for k, v in inversions.items()
        ]
        chains.append(d)
    nonplanar = sum(not c.planar for c in a.chains)
    if args.json:
        emit_json(
            {
                "F": args.dof,
                "n": args.links,
                "mj": args.mj,
                "fractionated": args.fractionated,
                "count": a.count,
                "nonplanar": nonplanar,
                "chains": chains,
            }
        )
        return 0
    kind = "simple and multiple joints" if args.mj else "simple joints"
    frac = ", fractionated included" if args.fractionated else ""
    lines = [
        f"F = {args.dof}, n = {args.links} ({kind}{frac}): {a.count} chains, "
        f"{nonplanar} not planar"
    ]
    by_code = Counter((c.V, c.MJA, c.LA) for c in a.chains)
    if by_code:
        lines.append("  [LA] / [MJA]: count")
        for (_, mja, la), count in sorted(by_code.items()):
            lines.append(f"  {list(la)} / {list(mja)}: {count}")
    if args.list:
        for d in chains:
            flag = "" if d["planar"] else "  non-planar"
            label = d["id"] or "-"
            lines.append(f"{label}  {d['LA']}/{d['MJA']}  {d['canonical']}{flag}  {d['joints']}")
            if d["name"]:
                lines.append(f"    {d['name']}")
            for inv in d["inversions"]:
                frames = ", ".join(map(str, inv["frames"]))
                lines.append(f"    {inv['name']}: frame link {frames}")
    emit_text("\n".join(lines))
    return 0


FLAGS = {"n": "--links", "workers": "--workers", "F": "--dof", "scheduler": "--scheduler"}
TOO_LARGE = "pass --large to enumerate anyway"


def _limit(args: argparse.Namespace) -> int | None:
    return None if args.large else CHAIN_LIMIT


def _refuse_large(text: str) -> MechanismError:
    return MechanismError(f"--links: {text.removeprefix('limit: ')}; {TOO_LARGE}")


def _check_sheet(args: argparse.Namespace) -> None:
    from mjstruct.plot.files import FIGURE_SUFFIXES, check_output

    if args.assur:
        raise MechanismError("--draw: atlas sheets draw chains, not Assur groups (--assur)")
    check_output(args.draw, FIGURE_SUFFIXES, name="--draw")


def _draw_sheet(args: argparse.Namespace, chains: list[Any], ids: dict[str, str]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.plot.atlas_sheet import write_atlas_sheet

    title = f"F = {args.dof}, n = {args.links}" + (", with multiple joints" if args.mj else "")
    write_atlas_sheet(chains, args.draw, ids, title=title, name="--draw")


def _run_atlas(args: argparse.Namespace, bar: Any) -> Any:
    from mjstruct.synthesis.atlas import atlas

    try:
        with flag_names(**FLAGS):
            return atlas(
                args.dof,
                args.links,
                mj=args.mj,
                fractionated=args.fractionated,
                workers=args.workers,
                progress=bar,
                scheduler=args.scheduler,
                limit=_limit(args),
            )
    except MechanismError as exc:
        if str(exc).startswith("limit:"):
            raise _refuse_large(str(exc)) from None
        raise


def _run_assur(args: argparse.Namespace) -> int:
    """``mjstruct atlas --assur --links n``."""
    from mjstruct.synthesis.assur_atlas import assur_atlas

    try:
        with flag_names(**FLAGS):
            groups = assur_atlas(args.links, workers=args.workers, limit=_limit(args))
    except MechanismError as exc:
        if str(exc).startswith("limit:"):
            raise _refuse_large(str(exc)) from None
        raise
    if args.json:
        emit_json({"n": args.links, "count": len(groups), "groups": [g.to_dict() for g in groups]})
        return 0
    lines = [f"Assur groups with {args.links} links (simple joints): {len(groups)}"]
    for (k, o), c in sorted(Counter((g.klass, g.order) for g in groups).items()):
        lines.append(f"  class {k}, order {o}: {c}")
    if args.list:
        for g in groups:
            lines.append(
                f"class {g.klass} order {g.order}  internal {[list(j) for j in g.joints]}  "
                f"external on {list(g.external)}"
            )
    emit_text("\n".join(lines))
    return 0


def _check_gear_flags(args: argparse.Namespace) -> None:
    """``--gears`` lists one-DOF trains of simple turning pairs: refuse the chain flags."""
    for flag, given in (
        ("--assur", args.assur),
        ("--mj", args.mj),
        ("--fractionated", args.fractionated),
        ("--draw", args.draw is not None),
        ("--dof", args.dof != 1),
        ("--scheduler", args.scheduler is not None),
        ("--large", args.large),
    ):
        if given:
            raise MechanismError(f"{flag}: not with --gears (the one-DOF gear-train atlas)")


def _run_gears(args: argparse.Namespace) -> int:
    """``mjstruct atlas --gears --links n``."""
    from mjstruct.gears.atlas import egt_atlas
    from mjstruct.synthesis.parallel import ProgressBar

    bar = ProgressBar.for_cli(f"gear trains n={args.links}", args.json)
    with flag_names(n="--links", workers="--workers"):
        a = egt_atlas(args.links, progress=bar, workers=args.workers)
    if args.json:
        emit_json(
            {
                "n": a.n,
                "count": a.count,
                "displacement_count": a.displacement_count,
                "trains": [t.to_dict() for t in a.trains],
            }
        )
        return 0
    lines = [
        f"one-DOF epicyclic gear trains, n = {a.n}: {a.count} rotation graphs, "
        f"{a.displacement_count} displacement graphs"
    ]
    if args.list:
        for t in a.trains:
            gears = " ".join(f"{x}-{y}/{c}" for x, y, c in t.gears)
            lines.append(f"{t.canonical}  gears (a-b/carrier) {gears}")
            for d in t.displacements:
                lines.append(
                    f"    axes {' '.join('{' + ','.join(map(str, x)) + '}' for x in d.axes)}"
                )
    emit_text("\n".join(lines))
    return 0
