"""Hypothesis strategies shared by the property tests."""

from __future__ import annotations

from hypothesis import strategies as st

from mjstruct.mechanism import Mechanism


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
