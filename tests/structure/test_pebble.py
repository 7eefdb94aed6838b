"""The (3,3) pebble game and generic mobility, checked against the numeric rank of the
velocity-constraint (rigidity) matrix at random geometry and against the formulas."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import catalog_root
from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.generic_mobility import generic_mobility
from mjstruct.structure.pebble import (
    PebbleGame,
    generic_dof,
    pebble_rank,
    rigid_components,
    rigidity,
)
from velocity_constraints import constraint_rows

EXAMPLES = sorted((catalog_root() / "examples").glob("*.json"))


# an independent reference: tests/velocity_constraints.py


def numeric_rank(m: Mechanism, seed: int = 0, **kw) -> int:
    rows = constraint_rows(m, np.random.default_rng(seed), **kw)
    return int(np.linalg.matrix_rank(rows)) if rows.size else 0


@st.composite
def chains(draw, max_links: int = 8, mj: bool = True) -> Mechanism:
    """Connected random chains; joints of 2 (or, with ``mj``, 3-4) links; some P."""
    n = draw(st.integers(3, max_links))
    links = [str(k) for k in range(n)]
    joints: list[tuple[str, list[str], str]] = []
    # a random spanning tree first, so that the chain is connected
    for k in range(1, n):
        joints.append((f"t{k}", [links[draw(st.integers(0, k - 1))], links[k]], "R"))
    for k in range(draw(st.integers(0, 2 * n))):
        size = draw(st.sampled_from([2, 2, 2, 3, 4] if mj else [2]))
        members = draw(st.permutations(links))[: min(size, n)]
        kind = "P" if len(members) == 2 and draw(st.integers(0, 5)) == 0 else "R"
        joints.append((f"j{k}", list(members), kind))
    return Mechanism.build(joints, frame="0")


# -- the game itself ------------------------------------------------------------------


def test_two_bodies_take_three_bars_then_reject():
    g = PebbleGame([3, 3])
    assert [g.add_edge(0, 1) for _ in range(4)] == [True, True, True, False]
    assert g.rank == 3 and g.free_pebbles == 3


def test_pinning_moves_all_free_pebbles_to_the_root():
    g = PebbleGame([3, 3, 3])
    for u, v in [(0, 1), (0, 1), (1, 2), (1, 2), (2, 0), (2, 0)]:
        assert g.add_edge(u, v)
    assert g.pin(2) == 3
    assert g.pebbles == [0, 0, 3] and g.out[2] == []


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_examples_generic_rank_matches_jacobian_rank(path):
    m = read_mechanism(path)
    assert pebble_rank(m) == numeric_rank(m)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_examples_generic_dof_equals_formula(path):
    """None of the examples has an over-constrained sub-chain, so F_generic = F."""
    m = read_mechanism(path)
    p = sum(j.multiplicity for j in m.joints)
    g = generic_mobility(m)
    assert g.F_formula == 3 * (m.n - 1) - 2 * p
    assert g.redundant == 0 and g.overconstrained == []
    assert g.F_generic == g.F_formula


@settings(max_examples=60, deadline=None)
@given(chains())
def test_random_chain_rank_equals_jacobian_rank(m):
    assert pebble_rank(m) == numeric_rank(m, seed=1)


@settings(max_examples=40, deadline=None)
@given(chains(), st.randoms(use_true_random=False))
def test_rank_does_not_depend_on_the_star_of_an_mj(m, rnd):
    shuffled = []
    for j in m.joints:
        ls = list(j.links)
        rnd.shuffle(ls)
        shuffled.append((j.id, ls, j.kind))
    assert pebble_rank(Mechanism.build(shuffled)) == pebble_rank(m)


@settings(max_examples=50, deadline=None)
@given(chains())
def test_generic_dof_is_formula_plus_redundancy(m):
    g = generic_mobility(m)
    assert g.F_generic == g.F_formula + g.redundant
    assert g.F_generic >= max(g.F_formula, 0)
    if not g.overconstrained:
        assert g.F_generic == g.F_formula
    # every over-constrained region is rigid: numeric DOF of the sub-chain is 0
    for links, k in g.overconstrained:
        inside = [j for j in m.joints if sum(x in links for x in j.links) >= 2]
        sub = Mechanism.build([(j.id, [x for x in j.links if x in links], j.kind) for j in inside])
        assert set(sub.links) == set(links)
        rows = sum(2 * (len(j.links) - 1) for j in sub.joints)
        assert 3 * (sub.n - 1) - numeric_rank(sub) == 0
        assert rows - numeric_rank(sub) >= k  # it holds at least its redundant bars


@pytest.mark.parametrize("order", [["3", "4", "5"], ["5", "3", "4"], ["4", "5", "3"]])
def test_mj_counts_its_pins_inside_every_sub_chain(order):
    # links 3, 4 share the MJ M and a second pin B: over-constrained by one whatever
    # link is listed first (a star from link 5 would hide it)
    m = Mechanism.build([("M", order), ("B", ["3", "4"])])
    r = rigidity(m)
    assert r.rank == numeric_rank(m) == 5
    assert r.dof == 1 and r.redundant in (("B",), ("M",))
    assert [set(links) for links, _ in r.regions] == [{"3", "4"}]
    assert [set(c) for c in rigid_components(m)] == [{"3", "4"}]


def test_redundancy_is_located_in_the_double_four_bar():
    # five-bar 0-1-2-3-4 (F = 2) carrying a double four-bar {4,5,6,7} (one pin too many)
    m = Mechanism.build(
        [("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]), ("C", [3, 4]), ("O2", [4, 0]),
         ("D", [4, 5]), ("E", [5, 6]), ("G", [6, 7]), ("H", [7, 4]), ("I", [5, 7])],
        frame=0, drivers=["O1"],
    )  # fmt: skip
    g = generic_mobility(m)
    assert (g.F_formula, g.F_generic, g.redundant) == (1, 2, 1)
    assert g.overconstrained == [(("4", "5", "6", "7"), 1)]
    assert ("4", "5", "6", "7") in g.rigid_subchains
    # one driver for two DOF: the rest of the five-bar still moves
    assert g.F_driven == 1 and set(g.free_links) == {"2", "3", "4", "5", "6", "7"}
    text = g.render()
    assert "over-constrained sub-chain {4, 5, 6, 7}" in text and "under-driven" in text
    d = g.to_dict()
    assert d["F_generic"] == 2 and d["rc_generic"] == -1
    assert d["overconstrained"] == [{"links": ["4", "5", "6", "7"], "redundant": 1}]


def test_triangle_is_rigid_and_four_bar_is_not():
    tri = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0])])
    assert rigid_components(tri) == [("0", "1", "2")] and generic_dof(tri) == 0
    four = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
    assert rigid_components(four) == [] and generic_dof(four) == 1


def test_rigid_components_agree_with_numeric_relative_mobility():
    # a four-bar whose coupler is a triangle of three pinned links {1,2,3}
    m = Mechanism.build(
        [("a", [1, 2]), ("b", [2, 3]), ("c", [3, 1]), ("d", [1, 4]), ("e", [4, 0]),
         ("f", [3, 5]), ("g", [5, 0])], frame=0,
    )  # fmt: skip
    assert rigid_components(m) == [("1", "2", "3")]
    assert 3 * (m.n - 1) - numeric_rank(m) == generic_dof(m) == 1
    # pinning the coupler to the frame as well makes everything one rigid body
    locked = Mechanism.build([(j.id, j.links) for j in m.joints] + [("h", [2, 0])], frame=0)
    assert [set(c) for c in rigid_components(locked)] == [set("012345")]
    loose = Mechanism.build([("a", [1, 2]), ("b", [2, 3]), ("c", [3, 1]), ("d", [1, 0])])
    assert rigid_components(loose) == [("1", "2", "3")]
    assert 3 * (loose.n - 1) - numeric_rank(loose) == generic_dof(loose) == 1


def test_drivers_over_and_under():
    four = read_mechanism(catalog_root() / "examples" / "four-bar.json")
    over = generic_mobility(four.with_drivers(["O1", "O2"]))
    assert over.redundant_drivers == ("O2",) and over.F_driven == 0 and over.rc_generic == 1
    assert "over-driven" in over.render()
    five = read_mechanism(catalog_root() / "examples" / "five-bar.json")
    under = generic_mobility(five.with_drivers(["O1"]))
    assert under.F_driven == 1 and under.redundant_drivers == ()
    assert set(under.free_links) == {"2", "3", "4"}
    ok = generic_mobility(five)
    assert ok.F_driven == 0 and ok.free_links == () and ok.rc_generic == 0


@settings(max_examples=40, deadline=None)
@given(chains(max_links=7))
def test_driven_dof_matches_jacobian_with_driver_rows(m):
    frame_joints = [j.id for j in m.joints if "0" in j.links][:2]
    m = m.with_drivers(frame_joints)
    g = generic_mobility(m)
    assert g.F_driven == 3 * (m.n - 1) - numeric_rank(m, fixed=["0"], drivers=m.drivers)


def test_rigidity_result_fields():
    r = rigidity(Mechanism.build([("a", [0, 1]), ("b", [0, 1])]))
    assert r.rank == 3 and r.dof == 0 and len(r.redundant) == 1


@settings(max_examples=40, deadline=None)
@given(chains(max_links=7), st.data())
def test_driver_balance_matches_jacobian_with_driver_rows(m, data):
    from mjstruct.structure.drivers import driver_balance

    ids = [j.id for j in m.joints]
    drivers = data.draw(st.lists(st.sampled_from(ids), unique=True, max_size=4))
    b = driver_balance(m, drivers)
    held = numeric_rank(m, fixed=["0"], drivers=drivers)
    assert b.dof_left == 3 * (m.n - 1) - held
    # each redundant driver adds a row but not to the rank
    assert len(b.redundant_drivers) == numeric_rank(m, fixed=["0"]) + len(drivers) - held


def test_a_copied_game_goes_on_independently():
    g = PebbleGame([3, 3, 3])
    for u, v in [(0, 1), (0, 1), (1, 2), (1, 2)]:
        assert g.add_edge(u, v)
    h = g.copy()
    assert [h.add_edge(0, 2) for _ in range(3)] == [True, True, False]
    assert (h.rank, g.rank, g.free_pebbles) == (6, 4, 5)
    assert [g.add_edge(0, 2) for _ in range(3)] == [True, True, False]
