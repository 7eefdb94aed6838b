"""GraphML and node-link JSON of the link–joint graph: exact round trips, attributes
that graph tools show, graphs written by other tools."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import networkx as nx
import pytest

from mjstruct.errors import MechanismError
from mjstruct.exchange.graph_formats import (
    mechanism_from_graph,
    mechanism_from_graphml,
    mechanism_from_node_link,
    mechanism_to_graph,
    mechanism_to_graphml,
    mechanism_to_node_link,
)
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.structure.isomorphism import canonical_code
from project_paths import EXAMPLES

ALL = sorted(EXAMPLES.glob("*.json"))


@pytest.mark.parametrize("path", ALL, ids=lambda p: p.stem)
def test_graphml_and_node_link_round_trips_are_exact(path):
    m = read_mechanism(path)
    for back in (
        mechanism_from_graphml(mechanism_to_graphml(m)),
        mechanism_from_node_link(json.loads(json.dumps(mechanism_to_node_link(m)))),
    ):
        assert back == m
        assert mechanism_to_dict(back) == mechanism_to_dict(m)  # geometry and extra keys too
        assert canonical_code(back, "mechanism") == canonical_code(m, "mechanism")


def test_graphml_declares_the_attributes_graph_tools_show():
    m = read_mechanism(EXAMPLES / "kin-radial-engine-5.json")
    root = ET.fromstring(mechanism_to_graphml(m))
    ns = {"g": "http://graphml.graphdrawing.org/xmlns"}
    keys = {
        (k.get("for"), k.get("attr.name")): k.get("attr.type") for k in root.findall("g:key", ns)
    }
    assert keys[("node", "multiplicity")] in ("int", "long")
    assert keys[("node", "frame")] == "boolean"
    assert keys[("node", "driver")] == "boolean"
    assert keys[("node", "type")] == "string"
    assert keys[("node", "x")] == "double"
    assert keys[("edge", "position")] in ("int", "long")
    # a plain networkx reader sees the bipartite graph with the MJ's degree
    g = nx.parse_graphml(mechanism_to_graphml(m))
    mj = [n for n, d in g.nodes(data=True) if d["part"] == "joint" and d["multiplicity"] > 1]
    assert len(mj) == 1 and g.degree(mj[0]) == g.nodes[mj[0]]["multiplicity"] + 1
    assert nx.is_bipartite(g)
    links = {n for n, d in g.nodes(data=True) if d["bipartite"] == 0}
    assert len(links) == m.n


def test_reads_the_graph_of_mechanism_graph():
    m = read_mechanism(EXAMPLES / "seed002-ex1-needle-drive.json")
    back = mechanism_from_graph(m.graph())
    assert back.frame == m.frame and back.drivers == m.drivers
    assert canonical_code(back, "mechanism") == canonical_code(m, "mechanism")


def test_reads_a_bipartite_graph_from_another_tool():
    g = nx.Graph()
    g.add_nodes_from(["ground", "crank", "rod", "rocker"], bipartite=0)
    g.add_nodes_from(["A", "B", "C", "D"], bipartite=1)
    g.add_edges_from([("A", "ground"), ("A", "crank"), ("B", "crank"), ("B", "rod")])
    g.add_edges_from([("C", "rod"), ("C", "rocker"), ("D", "rocker"), ("D", "ground")])
    m = mechanism_from_graph(g)
    four_bar = read_mechanism(EXAMPLES / "four-bar.json")
    assert canonical_code(m) == canonical_code(four_bar)
    assert m.frame is None and {j.id for j in m.joints} == {"A", "B", "C", "D"}


def test_bad_graphs_give_one_line_errors():
    g = mechanism_to_graph(read_mechanism(EXAMPLES / "four-bar.json"))
    g.add_node("stray")
    with pytest.raises(MechanismError, match="node 'stray' is neither a link nor a joint"):
        mechanism_from_graph(g)
    g = mechanism_to_graph(read_mechanism(EXAMPLES / "four-bar.json"))
    g.add_edge("joint:O1", "joint:A")
    with pytest.raises(MechanismError, match="joint 'O1' is joined to another joint"):
        mechanism_from_graph(g)
    with pytest.raises(MechanismError, match="not valid GraphML"):
        mechanism_from_graphml("<graphml><graph>")
    with pytest.raises(MechanismError, match="needs 'nodes' and 'edges'"):
        mechanism_from_node_link({"nodes": []})
    with pytest.raises(MechanismError, match="simple undirected"):
        mechanism_from_graph(nx.MultiGraph())


@pytest.mark.parametrize("value", ["1e400", "-inf", "nan"])
def test_coordinates_a_double_cannot_hold_are_bad_input_naming_the_joint(value):
    g = mechanism_to_graph(read_mechanism(EXAMPLES / "four-bar.json"))
    g.nodes["joint:B"]["y"] = value
    message = r"^joints\[2\]\.at: expected \[x, y\] with two finite"
    with pytest.raises(MechanismError, match=message):
        mechanism_from_graphml("\n".join(nx.generate_graphml(g)))
