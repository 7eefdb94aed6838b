"""Graph model conversions and the seed-000 incidence matrix."""

from __future__ import annotations

import json

import networkx as nx
import numpy as np

from mjstruct.io import from_link_graph, mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.mechanism import JOINT, LINK
from mjstruct.structure.incidence import incidence_matrix
from mjstruct.structure.isomorphism import canonical_code


def test_round_trip_keeps_everything(examples):
    for f in sorted(examples.glob("*.json")):
        m = read_mechanism(f)
        again = mechanism_from_dict(json.loads(json.dumps(mechanism_to_dict(m))))
        assert again == m and again.extra == m.extra


def test_mj_stays_whole_in_the_bipartite_graph(examples):
    m = read_mechanism(examples / "radial-engine-5.json")
    g = m.graph()
    assert g.degree((JOINT, "A")) == 6
    assert nx.is_bipartite(g)
    assert sum(1 for node in g if node[0] == LINK) == 12


def test_from_link_graph_matches_file(examples):
    g = nx.cycle_graph(4)
    m = from_link_graph(g, frame=0)
    assert canonical_code(m) == canonical_code(read_mechanism(examples / "four-bar.json"))


def test_zhivago_incidence_matches_seed_table_2(examples):
    m = read_mechanism(examples / "zhivago.json")
    inc = incidence_matrix(m)
    seed = np.array(
        [  # seed 000, Table 2 (rows: frame, links 1-5; columns k = 1..7)
            [-1, 0, 0, 0, 0, 0, -1],
            [1, -1, -1, 0, 0, 0, 0],
            [0, 1, 0, 0, -1, 0, 0],
            [0, 0, 1, -1, 0, 0, 0],
            [0, 0, 0, 1, 1, 1, 0],
            [0, 0, 0, 0, 0, -1, 1],
        ]
    )
    assert inc.matrix.tolist() == seed.tolist()
    assert inc.H.tolist() == [1] * 7
    assert not inc.matrix.sum(axis=0).any()


def test_mj_expands_into_simple_joints(examples):
    inc = incidence_matrix(read_mechanism(examples / "radial-engine-5.json"))
    a_cols = [c for c, j in zip(inc.columns, inc.joints, strict=True) if j == "A"]
    assert len(a_cols) == 5  # j = 5 simple-joint equivalents
    assert inc.matrix.shape == (12, 16)
    assert not inc.matrix.sum(axis=0).any()
    assert inc.H.tolist().count(2) == 5


def test_toml_round_trip_of_every_example(examples):
    from mjstruct.io import mechanism_to_toml, parse_mechanism

    for f in sorted(examples.glob("*.json")):
        m = read_mechanism(f)
        again = parse_mechanism(mechanism_to_toml(m), toml=True)
        assert again == m and again.extra == m.extra
