"""Property tests over random chains with multiple joints (hypothesis)."""

from __future__ import annotations

import networkx as nx
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.mechanism import Joint, Mechanism
from mjstruct.report import structural_report
from mjstruct.structure import mobility as mob
from mjstruct.structure.assortments import assortment, simple_joint_count
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.structure.loops import loop_assortment
from strategies import chains, relabelled


def expanded_simple_graph(m: Mechanism) -> nx.MultiGraph:
    """Every joint torn into m - 1 simple joints (an independent expansion: a path)."""
    g = nx.MultiGraph()
    g.add_nodes_from(m.links)
    for j in m.joints:
        for a, b in zip(j.links, j.links[1:], strict=False):
            g.add_edge(a, b)
    return g


@settings(max_examples=150, deadline=None)
@given(chains())
def test_loop_count_three_ways_and_avc(m):
    a = assortment(m)
    K_cycle = mob.cycle_rank(m)
    assert mob.loops_by_formula(a) == K_cycle
    assert mob.loops_by_joints(m.n, simple_joint_count(m)) == K_cycle
    assert mob.avc(a, K_cycle) == 0
    g = expanded_simple_graph(m)
    assert g.number_of_edges() - g.number_of_nodes() + 1 == K_cycle


@settings(max_examples=150, deadline=None)
@given(chains())
def test_dof_and_side_sums_agree(m):
    r = structural_report(m, with_loops=False)
    g = expanded_simple_graph(m)
    grubler = 3 * (g.number_of_nodes() - 1) - 2 * g.number_of_edges()
    assert r.F_values["loops"] == r.F_values["assortment"] == r.F_values["grubler"] == grubler
    d = r.to_dict()
    assert d["checks"]["S_L"]["sum_i_ni"] == d["checks"]["S_L"]["2(F+3K)-V"]
    assert d["rc"] == d["checks"]["rc"]["assortment"]


@settings(max_examples=60, deadline=None)
@given(chains(max_links=9, max_multiplicity=3))
def test_loops_sum_to_side_sum(m):
    la = loop_assortment(m)
    if la is not None:
        a = assortment(m)
        assert len(la.sizes) == mob.cycle_rank(m) + 1
        assert sum(la.sizes) == a.sides


@settings(max_examples=100, deadline=None)
@given(chains(), st.integers(0, 10**6))
def test_canonical_code_invariant_under_relabelling(m, seed):
    r = relabelled(m, seed)
    assert canonical_code(m) == canonical_code(r)
    assert canonical_code(m, "kinds") == canonical_code(r, "kinds")


@settings(max_examples=40, deadline=None)
@given(chains(max_links=9, max_multiplicity=3), st.integers(0, 10**6))
def test_loop_assortment_invariant_under_relabelling(m, seed):
    assert loop_assortment(m) == loop_assortment(relabelled(m, seed))


@settings(max_examples=100, deadline=None)
@given(chains(max_links=8))
def test_canonical_code_separates_non_isomorphic(m):
    # compare with networkx's VF2 on a modified chain: drop one joint member or add one
    other_joints = list(m.joints)
    j = other_joints[-1]
    if len(j.links) > 2:
        other_joints[-1] = Joint(j.id, j.links[:-1], j.kind)
    else:
        other_joints.append(Joint("extra", (m.links[0], m.links[-1]), "R"))
    try:
        other = Mechanism(links=m.links, joints=tuple(other_joints))
    except ValueError:
        return
    node_match = nx.algorithms.isomorphism.categorical_node_match("bipartite", None)
    iso = nx.is_isomorphic(m.graph(), other.graph(), node_match=node_match)
    assert (canonical_code(m) == canonical_code(other)) == iso
