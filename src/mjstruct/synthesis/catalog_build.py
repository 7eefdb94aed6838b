"""Writing the shipped chain catalogs from atlas runs (``catalogs/atlas/*.jsonl``).

Owns the records of one (F, n) catalog (the stable ids ``F1n10-0042`` for the
non-fractionated chains in the order of the atlas, ``F2n9-x0003`` for the fractionated
ones, with code and familiar name) and regenerating every shipped file atomically.
Reading and looking up are :mod:`mjstruct.synthesis.catalog`'s, which needs no atlas.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from mjstruct.synthesis import catalog


def catalog_records(F: int, n: int, workers: int = 1) -> list[dict[str, Any]]:
    """Enumerate (F, n) with multiple and fractionated chains; one record per chain."""
    from mjstruct.structure.assortments import Assortment
    from mjstruct.structure.codes import full_code, structural_code
    from mjstruct.synthesis.atlas import atlas
    from mjstruct.synthesis.names import familiar_names

    names = familiar_names()
    chains = atlas(F, n, mj=True, fractionated=True, workers=workers).chains
    out = []
    counters = {False: 0, True: 0}
    for c in chains:
        counters[c.fractionated] += 1
        cid = f"F{F}n{n}-{'x' if c.fractionated else ''}{counters[c.fractionated]:04d}"
        a = Assortment(LA=c.LA, MJA=c.MJA)
        rec = {
            "id": cid,
            "name": names.get(c.canonical),
            "cell": f"K{c.K}V{c.V}",
            "code": structural_code(a, c.K),
            "code_star": full_code(a, c.K),
            **c.to_dict(),
        }
        out.append(rec)
    return out


def write_catalogs(root: Path | None = None, workers: int = 1) -> dict[str, int]:
    """(Re)generate every shipped catalog file; returns {file name: chain count}."""
    root = root or catalog.atlas_dir()
    root.mkdir(parents=True, exist_ok=True)
    counts = {}
    for F, n in catalog.SHIPPED:  # read at the call (tests narrow it)
        recs = catalog_records(F, n, workers=workers)
        path = catalog.catalog_file(F, n, root)
        text = "".join(
            json.dumps(rec, ensure_ascii=False, separators=(",", ":")) + "\n" for rec in recs
        )
        _replace_file(path, text)
        counts[path.name] = len(recs)
    return counts


def _replace_file(path: Path, text: str) -> None:
    """Write ``text`` to a new file beside ``path`` and move it into place: an
    interrupted run leaves the old catalog, never half of a new one."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}-", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


if __name__ == "__main__":  # regenerate: python -m mjstruct.synthesis.catalog_build
    import sys

    for fname, count in write_catalogs(
        workers=int(sys.argv[1]) if len(sys.argv) > 1 else 1
    ).items():
        print(fname, count)
