"""``mjstruct lookup FILE``: find a mechanism's chain in the shipped catalogs."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

from mjstruct.cli.output import emit_json, emit_text

if TYPE_CHECKING:
    from mjstruct.synthesis.catalog import LookupResult


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file")
    p.add_argument("--json", action="store_true")


def run(args: argparse.Namespace) -> int:
    from mjstruct.io import read_mechanism
    from mjstruct.synthesis.catalog import lookup
    from mjstruct.synthesis.names import inversion_name, inversion_text

    m = read_mechanism(args.file)
    if "gears" in m.extra:  # the chain of the equivalent lower-pair chain
        from mjstruct.gears.structure import equivalent_chain

        m = equivalent_chain(m)
    r = lookup(m)
    inversion = inversion_name(m)
    reason = _reason(r)
    if args.json:
        out: dict[str, Any] = {"found": r.found, "canonical": r.canonical, "F": r.F, "n": r.n}
        out["inversion_name"] = inversion
        if r.found:
            rec = r.record
            out.update(
                {
                    k: rec[k]
                    for k in ("id", "name", "K", "V", "code", "code_star", "cell", "LA", "MJA")
                }
            )
            out["planar"] = rec["planar"]
            out["fractionated"] = rec["fractionated"]
        else:
            out["reason"] = reason
        emit_json(out)
        return 0
    if not r.found:
        emit_text(f"{args.file}: {reason}\ncanonical {r.canonical}")
        return 0
    rec = r.record
    emit_text(
        f"{args.file}: {rec['id']}" + (f" ({rec['name']})" if rec["name"] else "") + "\n"
        f"cell {rec['cell']}  code {rec['code']}  code* {rec['code_star']}  "
        f"F = {rec['F']}  n = {rec['n']}"
        + ("" if rec["planar"] else "  non-planar")
        + ("  fractionated" if rec["fractionated"] else "")
        + f"\ncanonical {rec['canonical']}"
        + (f"\nwith this frame: {inversion_text(inversion)}" if inversion else "")
    )
    return 0


def _reason(r: LookupResult) -> str:
    """The library's reason, with its advice given as the ``mjstruct atlas`` command."""
    from mjstruct.synthesis.catalog import not_shipped_reason

    if not r.atlas_args:
        return r.reason
    a = r.atlas_args
    flags = f"--dof {a['F']} --links {a['n']}"
    flags += " --mj" if a.get("mj") else ""
    flags += " --fractionated" if a.get("fractionated") else ""
    return not_shipped_reason(f"`mjstruct atlas {flags}`", r.n)
