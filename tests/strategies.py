"""Hypothesis strategies shared by the property tests."""

from __future__ import annotations

import random
from collections.abc import Iterator
from typing import Any

from hypothesis import strategies as st

from mjstruct.mechanism import Joint, Mechanism


@st.composite
def chains(draw: st.DrawFn, max_links: int = 12, max_multiplicity: int = 4) -> Mechanism:
    """Random connected link–joint chains with multiple joints (every link in a joint)."""
    n = draw(st.integers(2, max_links))
    placed = [0]
    joints: list[list[int]] = []
    rest = list(range(1, n))
    draw(st.randoms(use_true_random=False)).shuffle(rest)
    # connect every link to what is already placed, sometimes through an MJ
    while rest:
        m = draw(st.integers(2, min(max_multiplicity + 1, len(rest) + 1)))
        anchor = draw(st.sampled_from(placed))
        new = rest[: m - 1]
        rest = rest[m - 1 :]
        joints.append([anchor, *new])
        placed.extend(new)
    # extra joints close loops
    for _ in range(draw(st.integers(0, n + 2))):
        m = draw(st.integers(2, min(max_multiplicity + 1, n)))
        members = draw(st.lists(st.integers(0, n - 1), min_size=m, max_size=m, unique=True))
        joints.append(members)
    kinds = draw(st.lists(st.sampled_from("RRRP"), min_size=len(joints), max_size=len(joints)))
    return Mechanism.build(
        [(f"J{k}", [str(x) for x in js], kinds[k]) for k, js in enumerate(joints)], frame="0"
    )


def relabelled(m: Mechanism, seed: int) -> Mechanism:
    """The same chain with new ids and every list shuffled."""
    rng = random.Random(seed)
    names = list(m.links)
    new = [f"L{x}" for x in rng.sample(range(1000), len(names))]
    ren = dict(zip(names, new, strict=True))
    joints = []
    for k, j in enumerate(m.joints):
        links = [ren[x] for x in j.links]
        rng.shuffle(links)
        joints.append(Joint(f"Q{k}-{rng.random():.6f}", tuple(links), j.kind))
    rng.shuffle(joints)
    links_order = [ren[x] for x in names]
    rng.shuffle(links_order)
    return Mechanism(links=tuple(links_order), joints=tuple(joints))


def field_paths(d: Any, pre: tuple[Any, ...] = ()) -> Iterator[tuple[Any, ...]]:
    """Every path (keys and list indices) into a parsed file, the root ``()`` included."""
    yield pre
    if isinstance(d, dict):
        for k, v in d.items():
            yield from field_paths(v, (*pre, k))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from field_paths(v, (*pre, i))
