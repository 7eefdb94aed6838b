"""Familiar names of chains: the classic ones and the worked examples of
[MJ structure 2020]; and of the six-bar mechanisms by their frame.

A chain name belongs to a chain (no frame): it is keyed by the chain-level canonical
code, so any drawing of a Watt six-bar is called "Watt six-bar".  An inversion name
belongs to a chain with its frame chosen (drivers and joint kinds do not count): the
Watt chain gives Watt I (a binary frame) and Watt II (a ternary frame, two four-bars
in series); the Stephenson chain gives Stephenson I (the frame a binary link joining
both ternary links), Stephenson II (a binary link beside one ternary link) and
Stephenson III (a ternary frame: a four-bar with a dyad from its coupler to the
frame).  These are the names kinematics textbooks use; they are keyed by the
canonical code with the frame coloured.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
>>> familiar_name(m)
'four-bar'
>>> watt = [("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0]), ("e", [3, 4]),
...         ("f", [4, 5]), ("g", [5, 0])]
>>> [inversion_name(Mechanism.build(watt, frame=f)) for f in (0, 1)]
['Watt II six-bar', 'Watt I six-bar']
"""

from __future__ import annotations

from functools import cache, lru_cache

from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.isomorphism import canonical_code

# chain name -> joints as link lists (the classic chains)
CLASSIC: dict[str, list[list[int]]] = {
    "four-bar": [[0, 1], [1, 2], [2, 3], [3, 0]],
    "five-bar": [[0, 1], [1, 2], [2, 3], [3, 4], [4, 0]],
    "Watt six-bar": [[0, 1], [1, 2], [2, 3], [3, 0], [3, 4], [4, 5], [5, 0]],
    "Stephenson six-bar": [[0, 1], [0, 3], [1, 2], [2, 3], [1, 4], [4, 5], [5, 3]],
}

# inversion name -> (chain of CLASSIC, its frame link): the six-bar inversions
INVERSIONS: dict[str, tuple[str, int]] = {
    "Watt I six-bar": ("Watt six-bar", 1),  # binary frame
    "Watt II six-bar": ("Watt six-bar", 0),  # ternary frame
    "Stephenson I six-bar": ("Stephenson six-bar", 0),  # binary, beside both ternaries
    "Stephenson II six-bar": ("Stephenson six-bar", 4),  # binary, beside one ternary
    "Stephenson III six-bar": ("Stephenson six-bar", 1),  # ternary frame
}

# what each inversion's frame is, for the reports
FRAMES: dict[str, str] = {
    "Watt I six-bar": "a binary link",
    "Watt II six-bar": "a ternary link",
    "Stephenson I six-bar": "a binary link joining both ternary links",
    "Stephenson II six-bar": "a binary link beside one ternary link",
    "Stephenson III six-bar": "a ternary link",
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
    tables = [_names_of_size(n) for n in sorted(set(_classic_sizes().values()))]
    tables += [_names_of_size(n) for n in sorted(set(_example_sizes().values()))]
    by_name = {name: code for table in tables for code, name in table.items()}
    # the classic chains first, then the examples (in the order of their tables)
    out: dict[str, str] = {}
    for name in [*CLASSIC, *EXAMPLES.values()]:
        if name in by_name:
            out.setdefault(by_name[name], name)
    return out


def familiar_name(m: Mechanism) -> str | None:
    """The familiar name of ``m``'s chain, or None."""
    # only the named chains of m's size are canonised (a CLI start-up reads no others)
    table = _names_of_size(len(m.links))
    return table.get(canonical_code(m, "chain")) if table else None


def _classic_sizes() -> dict[str, int]:
    """Classic chain name -> its number of links."""
    return {name: len({x for js in joints for x in js}) for name, joints in CLASSIC.items()}


@lru_cache(maxsize=1)
def _example_sizes() -> dict[str, int]:
    """Shipped example stem -> its number of links (from the file, unvalidated: only
    to choose which examples to read and canonise for a chain of a given size)."""
    import json

    from mjstruct.catalog_files import example_path

    out = {}
    for stem in EXAMPLES:
        path = example_path(stem)
        if path.is_file():
            data = json.loads(path.read_text(encoding="utf-8"))
            out[stem] = len({str(x) for j in data.get("joints", []) for x in j.get("links", [])})
    return out


@cache
def _names_of_size(size: int) -> dict[str, str]:
    """Canonical code -> familiar name of the named chains with ``size`` links."""
    out: dict[str, str] = {}
    sizes = _classic_sizes()
    for name, joints in CLASSIC.items():
        if sizes[name] == size:
            m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)])
            out[canonical_code(m, "chain")] = name
    stems = [s for s, n in _example_sizes().items() if n == size]
    if stems:
        from mjstruct.catalog_files import example_path
        from mjstruct.io import read_mechanism

        for stem in stems:
            out.setdefault(
                canonical_code(read_mechanism(example_path(stem)), "chain"), EXAMPLES[stem]
            )
    return out


def _frame_code(m: Mechanism) -> str:
    """Canonical code of ``m``'s chain with its frame coloured (all joints revolute, no
    drivers): what an inversion name depends on."""
    plain = Mechanism.build([(j.id, j.links) for j in m.joints], frame=m.frame)
    return canonical_code(plain, "mechanism")


@lru_cache(maxsize=1)
def inversion_names() -> dict[str, str]:
    """Canonical code with the frame coloured (see :func:`inversion_name`) -> name."""
    out = {}
    for name, (chain, frame) in INVERSIONS.items():
        joints = CLASSIC[chain]
        m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(joints)], frame=frame)
        out[_frame_code(m)] = name
    return out


def inversion_name(m: Mechanism) -> str | None:
    """The familiar name of ``m`` as a mechanism (its chain with the frame chosen):
    Watt I/II and Stephenson I/II/III for the six-bars; None without a frame or a name.
    Revolute and prismatic joints alike, whatever the drivers.
    """
    expect_mechanism(m)
    if m.frame is None:
        return None
    return inversion_names().get(_frame_code(m))


def chain_inversions(m: Mechanism) -> dict[str, list[str]]:
    """For a named chain, each inversion name with the links that give it as the frame
    (file order); empty for a chain with no named inversions.

    >>> from mjstruct.mechanism import Mechanism
    >>> steph = Mechanism.build([("a", [0, 1]), ("b", [0, 3]), ("c", [1, 2]), ("d", [2, 3]),
    ...                          ("e", [1, 4]), ("f", [4, 5]), ("g", [5, 3])])
    >>> chain_inversions(steph)
    {'Stephenson I six-bar': ['0', '2'], 'Stephenson II six-bar': ['4', '5'], \
'Stephenson III six-bar': ['1', '3']}
    """
    expect_mechanism(m)
    chain = familiar_name(m)
    if chain not in {c for c, _ in INVERSIONS.values()}:
        return {}
    out: dict[str, list[str]] = {}
    for link in m.links:
        name = inversion_name(Mechanism.build([(j.id, j.links) for j in m.joints], frame=link))
        if name is not None:
            out.setdefault(name, []).append(link)
    return dict(sorted(out.items()))


def inversion_text(name: str | None) -> str:
    """An inversion name with what its frame is, for a text report ("" for None).

    >>> inversion_text("Stephenson II six-bar")
    'Stephenson II six-bar (frame: a binary link beside one ternary link)'
    """
    return "" if name is None else f"{name} (frame: {FRAMES[name]})"
