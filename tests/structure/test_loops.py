"""Loop assortment [L]: which drawing is reported, and that it ignores labels and order."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure import loops
from mjstruct.structure.assortments import assortment
from mjstruct.structure.loops import loop_assortment
from mjstruct.structure.mobility import cycle_rank
from strategies import chains, relabelled


def test_excavator_gets_the_designers_drawing(examples):
    # [4 4 4 4 13] and not, e.g., [4 4 4 8 9]: the lexicographically smallest drawing
    la = loop_assortment(read_mechanism(examples / "seed002-ex3-excavator.json"))
    assert la is not None and la.rule == "minimal" and la.sizes == (4, 4, 4, 4, 13)


def test_canonical_rule_is_label_independent():
    # a hub joined to the frame by nine chains of 1..9 binary links: no two alike (the
    # radial engine's equal cylinders are parallel chains, found exactly now), 8!^2
    # rotations at the two ends
    joints = []
    for k in range(1, 10):
        path = ["hub", *(f"c{k}_{i}" for i in range(k)), "frame"]
        joints += [(f"J{k}_{i}", [a, b]) for i, (a, b) in enumerate(itertools.pairwise(path))]
    m = Mechanism.build(joints, frame="frame")
    la = loop_assortment(m)
    assert la is not None and la.rule == "canonical"
    assert sum(la.sizes) == assortment(m).sides
    for seed in range(5):
        assert loop_assortment(relabelled(m, seed)) == la


@settings(max_examples=60, deadline=None)
@given(chains(max_links=9, max_multiplicity=3), st.integers(0, 10**6))
def test_canonical_drawing_never_beats_the_minimal_one(m, seed):
    exact = loop_assortment(m)
    canonical = loops._canonical_faces(m)
    if exact is None:
        assert canonical is None
        return
    assert canonical is not None
    assume(exact.rule == "minimal")  # beyond the exact limit both rules are the same drawing
    assert exact.sizes <= canonical  # minimal over all drawings, canonical is one of them
    assert loops._canonical_faces(relabelled(m, seed)) == canonical


def test_nonplanar_k33_chain_has_no_loops():
    # K3,3 as a link graph: every edge a simple joint
    joints = [(f"J{a}{b}", [f"a{a}", f"b{b}"]) for a in range(3) for b in range(3)]
    m = Mechanism.build(joints)
    assert loop_assortment(m) is None
    assert not loops.is_planar(m)


@pytest.mark.parametrize(
    ("joints", "sizes"),
    [
        ([("J0", ["0", "1"]), ("J1", ["0", "1"])], (2, 2)),
        ([("J0", ["0", "1"]), ("J1", ["0", "1"]), ("J2", ["0", "1"])], (2, 2, 2)),
        ([("A", ["0", "1"]), ("B", ["0", "1"]), ("C", ["1", "2"]), ("D", ["2", "0"])], (2, 3, 3)),
    ],
)
def test_parallel_joints_whose_loop_is_the_chains_own(joints, sizes):
    """Two links joined by k joints: k two-link loops (k − 1 inside, one outside), also
    when the parallel joints make the chain's only loop."""
    m = Mechanism.build(joints, frame="0")
    la = loop_assortment(m)
    assert la is not None and la.sizes == sizes
    assert len(la.sizes) == cycle_rank(m) + 1
