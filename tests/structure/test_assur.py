"""Assur-group decomposition: worked cases, and properties checked numerically
(each group has zero DOF with its external pins fixed and no smaller part does)."""

from __future__ import annotations

import itertools
import json
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import read_mechanism
from mjstruct.mechanism import Joint, Mechanism
from mjstruct.structure.assur import (
    Decomposition,
    assur_groups,
    driver_choices,
    group_class,
)
from mjstruct.testing import random_mechanism
from velocity_constraints import constraint_rows


def example(name: str) -> Mechanism:
    return read_mechanism(example_path(name))


def summary(d: Decomposition) -> list[tuple[tuple[str, ...], int, int]]:
    return [(g.links, g.klass, g.order) for g in d.groups]


# -- numeric reference --------------------------------------------------------------


def dof_with_fixed(m: Mechanism, moving: set[str], fixed: set[str], seed: int = 3) -> int:
    """DOF of the links ``moving`` when the links ``fixed`` are held, at random geometry.

    Only joints among moving and fixed links count; drivers inside count as welds.
    """
    keep = moving | fixed
    joints = []
    for j in m.joints:
        inside = tuple(x for x in j.links if x in keep)
        if len(inside) >= 2:
            joints.append(Joint(j.id, inside, j.kind))
    drivers = [d for d in m.drivers if all(x in keep for x in m.joint(d).links[:2])]
    # the sub-chain may be disconnected (fixed links apart), so no Mechanism here
    by_id = {j.id: j for j in joints}
    sub = SimpleNamespace(links=sorted(keep), joints=joints, joint=by_id.__getitem__)
    rows = constraint_rows(sub, np.random.default_rng(seed), fixed=fixed, drivers=drivers)
    rank = int(np.linalg.matrix_rank(rows)) if rows.size else 0
    return 3 * len(moving) - rank


def check_decomposition(m: Mechanism, d: Decomposition, minimal_up_to: int = 5) -> None:
    moving = [x for x in m.links if x != m.frame]
    owned = [b for _, _, b in d.initial] + [x for g in d.groups for x in g.links]
    assert sorted(owned) == sorted(moving), "groups and initial mechanisms partition the links"
    # where each link's position is known: the frame's body, then group after group
    placed_top = {m.frame}
    for _, a, b in d.initial:
        if a in placed_top:
            placed_top.add(b)
    placed_in: dict[tuple[str, ...], set[str]] = {}
    for g in d.groups:
        assert 3 * len(g.bodies) == 2 * g.pairs, "3 n_g = 2 p_g"
        at = [sum(any(x in b for x in m.joint(j).links) for b in g.bodies) for j in g.external]
        assert g.klass >= 2 and g.order == sum(at) and min(at) >= 1
        if g.within:  # solved in the frame of its reference body, inside a rigid cluster
            placed = placed_in.setdefault(g.within, set())
            if not placed:
                placed |= _welded(d, g.reference)
        else:
            placed = placed_top
        group_links = {x for b in g.bodies for x in b}
        assert not group_links & placed
        for jid in g.external:
            assert set(m.joint(jid).links) & placed, f"{jid} attaches to a placed link"
        assert dof_with_fixed(m, group_links, placed) == 0, "zero DOF with pins fixed"
        if len(g.bodies) <= minimal_up_to:
            for k in range(1, len(g.bodies)):
                for part in itertools.combinations(g.bodies, k):
                    links = {x for b in part for x in b}
                    assert dof_with_fixed(m, links, placed) > 0, "the group is minimal"
        placed |= group_links


def _welded(d: Decomposition, root: str) -> set[str]:
    out = {root}
    for _, a, b in d.initial:
        if a in out:
            out.add(b)
    return out


# -- the cases ----------------------------------------------------------------


@pytest.mark.parametrize("name", ["four-bar", "slider-crank"])
def test_four_bar_and_slider_crank_are_one_dyad(name):
    m = example(name)
    d = assur_groups(m)
    assert summary(d) == [(("2", "3"), 2, 2)] and d.mechanism_class == 2
    assert d.initial == (("O1", "0", "1"),)
    check_decomposition(m, d)


@pytest.mark.parametrize("name", ["watt", "stephenson"])
def test_six_bars_are_two_dyads(name):
    m = example(name)
    d = assur_groups(m)
    assert [g.klass for g in d.groups] == [2, 2] and d.mechanism_class == 2
    check_decomposition(m, d)


def test_seed003_is_crank_plus_one_class_iv_group():
    m = example("class-iv-seed003")
    d = assur_groups(m)
    assert d.initial == (("O", "0", "1"),)
    assert summary(d) == [(("2", "3", "4", "5"), 4, 2)]
    assert set(d.groups[0].external) == {"A", "F"}
    assert set(d.groups[0].internal) == {"B", "C", "D", "E"}
    check_decomposition(m, d)


def test_zhivago_driven_at_the_frame():
    m = example("zhivago")
    # driven at the frame joint C (rocker 5): the 4-contour A-B-D-E is one class-IV group
    at_c = assur_groups(m, ["C"])
    assert summary(at_c) == [(("1", "2", "3", "4"), 4, 2)]
    check_decomposition(m.with_drivers(["C"]), at_c)
    # driven at O (the ternary link OAE): the legs 2, 3, 5 hold the ternary link BDG,
    # a triad (class III, order 3); see docs/assur.md on why this is not class IV
    at_o = assur_groups(m)
    assert summary(at_o) == [(("2", "3", "4", "5"), 3, 3)]
    check_decomposition(m, at_o)


def test_zhivago_driven_at_the_inner_joint_e_gives_class_ii_only():
    m = example("zhivago").with_drivers(["E"])
    d = assur_groups(m)
    assert d.initial == (("E", "1", "3"),)
    assert [g.klass for g in d.groups] == [2, 2] and d.mechanism_class == 2
    inner, outer = d.groups
    # triangle A-B-D closed on the body {1, 3} welded by the driver, in link 1's frame
    assert inner.links == ("2", "4") and inner.reference == "1"
    assert set(inner.within) == {"1", "2", "3", "4"} and set(inner.external) == {"A", "D"}
    # then the rigid cluster and link 5 form a dyad relative to the frame
    assert outer.reference == "0" and outer.within == ()
    assert outer.links == ("1", "5") and set(outer.external) == {"O", "C"}
    assert sorted(map(set, outer.bodies), key=len) == [{"5"}, {"1", "2", "3", "4"}]
    check_decomposition(m, d)


@pytest.mark.parametrize("name,cyl", [("radial-engine-5", 5), ("radial-engine-9", 9)])
def test_radial_engine_hangs_one_dyad_per_cylinder_on_the_mj(name, cyl):
    m = example(name)
    d = assur_groups(m)
    assert d.initial == (("O", "0", "1"),)
    assert len(d.groups) == cyl and d.mechanism_class == 2
    rods = set(m.joint("A").links) - {"1"}
    pistons = {x for j in m.joints if j.kind == "P" for x in j.links} - {"0"}
    for g in d.groups:
        assert g.klass == 2 and g.order == 2
        rod, piston = g.links
        assert rod in rods and piston in pistons  # each dyad is a rod and its piston
        assert "A" in g.external  # the MJ is one external pin, never torn into pairs
        assert all(jid in {j.id for j in m.joints} for jid in g.joints)
    assert {g.links[0] for g in d.groups} == rods
    text = d.render()
    assert text.count("Assur groups") == 1 and "class II" in text
    check_decomposition(m, d)


def test_excavator_three_prismatic_drivers_gives_dyads_only():
    m = example("seed002-ex3-excavator")
    d = assur_groups(m)
    assert len(d.initial) == 3 and all(m.joint(x).kind == "P" for x, _, _ in d.initial)
    assert {g.klass for g in d.groups} == {2} and d.mechanism_class == 2
    check_decomposition(m, d)


def test_triad_mechanism_is_class_iii():
    m = example("triad-class-iii")
    d = assur_groups(m)
    assert summary(d) == [(("2", "3", "4", "5"), 3, 3)] and d.mechanism_class == 3
    check_decomposition(m, d)


@pytest.mark.parametrize(
    "name", ["seed002-ex1-needle-drive", "seed002-ex4-swivel-bucket", "seed002-ex5-24-link"]
)
def test_other_seed_examples_decompose_into_valid_groups(name):
    m = example(name)
    check_decomposition(m, assur_groups(m), minimal_up_to=4)


def test_mj_inside_a_group_counts_its_simple_joint_equivalents():
    # seed 003's class-IV ring with C and D made one MJ M on link 2: links 3, 4, 5
    # then close a rigid triangle (3 and 4 meet at M, both pin to 5)
    m = Mechanism.build(
        [("O", [0, 1]), ("A", [1, 2]), ("M", [2, 3, 4]), ("B", [3, 5]), ("E", [4, 5]),
         ("F", [5, 0])], frame=0, drivers=["O"],
    )  # fmt: skip
    # as one group: M is 2 simple joints, 3 n_g = 2 p_g = 12, a 3-link contour: class III
    assert group_class("2345", [["2", "3", "4"], ["3", "5"], ["4", "5"]]) == 3
    d = assur_groups(m)
    # the rigid triangle is solved first in its own frame, then moves with link 2 as a dyad
    inner, outer = d.groups
    assert inner.within and set(inner.within) == {"3", "4", "5"} and inner.klass == 2
    assert outer.within == () and outer.klass == 2 and "2" in outer.links
    assert "M" in outer.internal and d.mechanism_class == 2
    check_decomposition(m, d)


def test_mj_star_order_does_not_change_the_groups():
    # the MJ listed from a later link must not merge the dyad {2,3} with link 4
    joints = [("O1", [0, 1]), ("A", [2, 1]), ("B", [3, 0]), ("M", [4, 2, 3]), ("C", [4, 5]),
              ("D", [5, 0])]  # fmt: skip
    d = assur_groups(Mechanism.build(joints, frame=0, drivers=["O1"]))
    assert [g.links for g in d.groups] == [("2", "3"), ("4", "5")]


def test_under_and_over_driven_are_refused_with_one_line():
    with pytest.raises(MechanismError, match="under-driven"):
        assur_groups(example("five-bar"), ["O1"])
    with pytest.raises(MechanismError, match="over-constrained"):
        assur_groups(example("four-bar"), ["O1", "O2"])
    with pytest.raises(MechanismError, match="frame"):
        assur_groups(Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0])]))


def test_driver_choices_rank_by_class_and_report_bad_choices():
    m = example("zhivago")
    choices = driver_choices(m)
    assert [(c.drivers, c.mechanism_class) for c in choices] == [(("O",), 3), (("C",), 4)]
    every = driver_choices(m, any_joint=True)
    assert len(every) == len(m.joints) and all(c.status == "ok" for c in every)
    assert [c.mechanism_class for c in every] == sorted(c.mechanism_class for c in every)
    assert {c.drivers[0] for c in every if c.mechanism_class == 2} == {"A", "B", "D", "E"}
    five = driver_choices(example("five-bar"), count=1)
    assert {c.status for c in five} == {"under-driven"} and all(c.dof_left == 1 for c in five)
    four = driver_choices(example("four-bar"), count=2)
    assert [(c.status, c.redundant) for c in four] == [("over-driven", 1)]
    assert four[0].to_dict()["status"] == "over-driven"


# -- properties on random mechanisms (F = N = 1) ------------------------------------


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 8), st.integers(0, 10**6), st.sampled_from([0.0, 0.3, 0.6]))
def test_random_mechanisms_decompose_into_minimal_solvable_groups(groups, seed, mj):
    m = random_mechanism(groups, seed=seed, mj=mj)
    d = assur_groups(m)
    check_decomposition(m, d, minimal_up_to=4)
    from mjstruct.structure.generic_mobility import generic_mobility

    g = generic_mobility(m)
    assert g.F_generic == g.F_formula == len(m.drivers) == 1


# -- CLI -----------------------------------------------------------------------------


def test_cli_json_contract(capsys):
    assert main(["assur", str(example_path("class-iv-seed003")), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["mechanism_class"] == 4
    (g,) = out["groups"]
    assert {"links", "joints", "class", "order"} <= set(g)
    assert (g["links"], g["class"], g["order"]) == (["2", "3", "4", "5"], 4, 2)


def test_cli_drivers_override_and_all_choices(capsys):
    path = str(example_path("zhivago"))
    assert main(["assur", path, "--drivers", "E", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["drivers"] == ["E"] and out["mechanism_class"] == 2
    assert main(["assur", path, "--all-choices", "--any-joint"]) == 0
    text = capsys.readouterr().out
    assert "Driver choices" in text and "E: class II" in text


def test_cli_bad_input_exits_2_with_one_line(capsys):
    assert main(["assur", str(example_path("four-bar")), "--drivers", "X"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'X'" in err
    assert main(["assur", str(example_path("five-bar")), "--drivers", "O1"]) == 2
    assert "under-driven" in capsys.readouterr().err


def test_zhivago_driven_at_c_is_the_seed003_mechanism():
    """Why C (not O) gives the class-IV group: the same mechanism as seed 003."""
    from mjstruct.structure.isomorphism import canonical_code

    z, s = example("zhivago"), example("class-iv-seed003")
    same = canonical_code(z.with_drivers(["C"]), level="mechanism")
    assert same == canonical_code(s, level="mechanism")
    assert canonical_code(z, level="mechanism") != canonical_code(s, level="mechanism")


def test_cli_assur_imports_no_heavy_library():
    import subprocess
    import sys

    code = (
        "import sys; from mjstruct.cli.main import main; "
        f"main(['assur', {str(example_path('radial-engine-5'))!r}, '--json']); "
        "print([k for k in ('sympy', 'matplotlib', 'scipy') if k in sys.modules], "
        "file=sys.stderr)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0 and done.stderr.strip() == "[]"


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 5), st.integers(0, 10**6), st.data())
def test_random_inner_drivers_give_valid_nested_decompositions(groups, seed, data):
    m = random_mechanism(groups, seed=seed, mj=0.3)
    driver = data.draw(st.sampled_from([j.id for j in m.joints]))
    m = m.with_drivers([driver])
    choices = driver_choices(m, any_joint=True, count=1)
    assert len(choices) == len(m.joints)
    choice = next(c for c in choices if c.drivers == (driver,))
    if choice.status != "ok":
        with pytest.raises(MechanismError):
            assur_groups(m)
        return
    d = assur_groups(m)
    assert d.mechanism_class == choice.mechanism_class
    check_decomposition(m, d, minimal_up_to=4)


def test_crank_alone_is_an_initial_mechanism_without_groups():
    d = assur_groups(Mechanism.build([("O", [0, 1])], frame=0, drivers=["O"]))
    assert d.groups == () and d.mechanism_class == 1 and d.initial == (("O", "0", "1"),)
    assert "Mechanism class: I (1)" in d.render()


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(st.integers(0, 6), min_size=2, max_size=3, unique=True), max_size=9))
def test_longest_contour_against_networkx_shortest_cycles(internal):
    import networkx as nx

    from mjstruct.structure.assur.contours import longest_contour

    g = nx.Graph()
    for k, touched in enumerate(internal):
        g.add_edges_from((("joint", k), ("body", b)) for b in touched)
    expected = 0
    for u, v in list(g.edges):
        g.remove_edge(u, v)
        if nx.has_path(g, u, v):
            expected = max(expected, (nx.shortest_path_length(g, u, v) + 1) // 2)
        g.add_edge(u, v)
    assert longest_contour(internal) == expected


def test_solving_order_is_fixed_by_the_depth_first_search():
    """The groups' order is fixed by construction (the depth-first completion order of
    the components), dependencies first; the components are networkx's."""
    import random

    import networkx as nx

    from mjstruct.structure.assur.decomposition import _dependency_order

    out = [[1], [2], [1], [0, 4], [3], []]
    order = _dependency_order(out, skip=5)
    assert order == [[1, 2], [0], [3, 4]]
    rng = random.Random(4)
    for _ in range(200):
        n = rng.randint(1, 25)
        out = [[rng.randrange(n) for _ in range(rng.randint(0, 3))] for _ in range(n)]
        skip = rng.randrange(n)
        order = _dependency_order(out, skip)
        g = nx.DiGraph()
        g.add_nodes_from(v for v in range(n) if v != skip)
        g.add_edges_from((v, w) for v in range(n) if v != skip for w in out[v] if w != skip)
        assert sorted(order) == sorted(sorted(c) for c in nx.strongly_connected_components(g))
        assert all(c == sorted(c) for c in order)
        place = {v: k for k, comp in enumerate(order) for v in comp}
        assert all(
            place[w] <= place[v]
            for v, heads in enumerate(out)
            if v != skip
            for w in heads
            if w != skip
        )
