"""Familiar names of chains: the classic ones and the worked examples of
[MJ structure 2020].

A name belongs to a chain (no frame): it is keyed by the chain-level canonical code,
so any drawing of a Watt six-bar is called "Watt six-bar".

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
>>> familiar_name(m)
'four-bar'
"""

from __future__ import annotations

from functools import lru_cache

from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import canonical_code

# chain name -> joints as link lists (the classic chains)
CLASSIC: dict[str, list[list[int]]] = {
    "four-bar": [[0, 1], [1, 2], [2, 3], [3, 0]],
    "five-bar": [[0, 1], [1, 2], [2, 3], [3, 4], [4, 0]],
    "Watt six-bar": [[0, 1], [1, 2], [2, 3], [3, 0], [3, 4], [4, 5], [5, 0]],
    "Stephenson six-bar": [[0, 1], [0, 3], [1, 2], [2, 3], [1, 4], [4, 5], [5, 3]],
}

# shipped example files whose chains are named after the worked examples of
# [MJ structure 2020]
EXAMPLES: dict[str, str] = {
    "seed002-ex1-needle-drive": "needle drive chain ([MJ structure 2020], example 1)",
    "seed002-ex4-swivel-bucket": "swivel bucket drive chain ([MJ structure 2020], example 4)",
    "seed002-ex3-excavator": "excavator boom-arm-bucket chain ([MJ structure 2020], example 3)",
    "radial-engine-5": "5-cylinder radial engine chain ([MJ structure 2020], example 2)",
}


@lru_cache(maxsize=1)
def familiar_names() -> dict[str, str]:
    """Canonical code (chain level) -> familiar name."""
    out: dict[str, str] = {}
    for name, joints in CLASSIC.items():
        m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)])
        out[canonical_code(m, "chain")] = name
    from mjstruct.catalog_files import example_path
    from mjstruct.io import read_mechanism

    for stem, name in EXAMPLES.items():
        path = example_path(stem)
        if path.is_file():
            out.setdefault(canonical_code(read_mechanism(path), "chain"), name)
    return out


def familiar_name(m: Mechanism) -> str | None:
    """The familiar name of ``m``'s chain, or None."""
    return familiar_names().get(canonical_code(m, "chain"))
