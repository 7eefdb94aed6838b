"""The bipartite link–joint graph as GraphML and node-link JSON (through networkx).

Graph tools (Gephi, yEd, Cytoscape, networkx itself) open these files; the
attributes carry everything a mechanism file holds, so the round trip is exact.

Nodes are ``link:<id>`` and ``joint:<id>``; every node has ``part`` (``link`` or
``joint``), ``label`` (the mechanism's id), ``index`` (place in the file) and
``bipartite`` (0 for links, 1 for joints, networkx's convention).  Links carry
``frame`` (bool); joints carry ``type`` (``R``/``P``), ``driver`` (bool),
``multiplicity`` (links − 1) and, when the file has geometry, ``x``, ``y`` and for a
prismatic joint ``axis_x``, ``axis_y``.  An edge joins a joint to each of its links,
with ``position``, the link's place in the joint's list (the first link is the
reference of the joint's coordinate).  A gear pair (the file's ``gears``) is an edge
between its two links with ``pair`` = ``gear``, ``gear_id`` and ``gear_type``
(``external``, ``internal``, ``rack``); a graph with such edges and no ``extra``
gets its ``gears`` from them.  Graph attributes: ``name``, and as JSON text
``points`` and ``extra`` (masses, loads) when present.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("O", [0, 1]), ("A", [1, 2, 3]), ("B", [2, 0]), ("C", [3, 0])],
...                     frame=0, drivers=["O"])
>>> g = mechanism_to_graph(m)
>>> g.nodes["joint:A"]["multiplicity"], g.nodes["link:0"]["frame"]
(2, True)
>>> mechanism_from_graphml(mechanism_to_graphml(m)) == m
True
>>> mechanism_from_node_link(mechanism_to_node_link(m)) == m
True
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError
from mjstruct.gear_pairs import read_gear_pairs
from mjstruct.mechanism import JOINT, LINK, Joint, Mechanism, Point

if TYPE_CHECKING:
    import networkx as nx


def mechanism_to_graph(m: Mechanism) -> nx.Graph:
    """The link–joint graph of ``m`` with string node ids and exchange attributes."""
    import networkx as nx

    g = nx.Graph()
    if m.name:
        g.graph["name"] = m.name
    if m.points:
        g.graph["points"] = json.dumps(
            [{"id": p.id, "link": p.link, "at": list(p.at)} for p in m.points]
        )
    if m.extra:
        g.graph["extra"] = json.dumps(dict(m.extra), allow_nan=False)
    for k, link in enumerate(m.links):
        g.add_node(
            f"{LINK}:{link}", part=LINK, label=link, index=k, bipartite=0, frame=link == m.frame
        )
    drivers = set(m.drivers)
    for k, j in enumerate(m.joints):
        attrs: dict[str, Any] = {
            "part": JOINT,
            "label": j.id,
            "index": k,
            "bipartite": 1,
            "type": j.kind,
            "driver": j.id in drivers,
            "multiplicity": j.multiplicity,
        }
        if j.at is not None:
            attrs["x"], attrs["y"] = j.at
        if j.axis is not None:
            attrs["axis_x"], attrs["axis_y"] = j.axis
        g.add_node(f"{JOINT}:{j.id}", **attrs)
        for pos, link in enumerate(j.links):
            g.add_edge(f"{JOINT}:{j.id}", f"{LINK}:{link}", position=pos)
    for gear in _gear_entries(m.extra.get("gears")):  # higher pairs: link-link edges
        a, b = (f"{LINK}:{x}" for x in gear["links"])
        g.add_edge(
            a, b, pair="gear", gear_id=str(gear["id"]), gear_type=gear.get("type", "external")
        )
    return g


def _gear_entries(raw: Any) -> list[Mapping[str, Any]]:
    """The file's gear pairs (checked when it was read) as plain objects."""
    if not isinstance(raw, list):
        return []
    return [e for e in raw if isinstance(e, Mapping) and len(e.get("links", ())) == 2]


def _part(node: Any, data: Mapping[str, Any]) -> tuple[str, str]:
    """(``link``/``joint``, id) of a node, from our attributes or networkx conventions."""
    if data.get("part") in (LINK, JOINT):
        label = data.get("label")
        ident = str(label) if label is not None else str(node).split(":", 1)[-1]
        return str(data["part"]), ident
    if isinstance(node, tuple) and len(node) == 2 and node[0] in (LINK, JOINT):
        return str(node[0]), str(node[1])  # the graph of Mechanism.graph()
    if data.get("bipartite") in (0, 1):
        label = data.get("label")
        return (LINK, JOINT)[int(data["bipartite"])], str(node if label is None else label)
    raise MechanismError(
        f"graph: node {node!r} is neither a link nor a joint (give it part='link' or "
        "'joint', or bipartite=0 or 1)"
    )


def _flag(value: Any) -> bool:
    # GraphML written by other tools may carry booleans as text
    if isinstance(value, str):
        return value.strip().lower() in ("true", "1", "yes")
    return bool(value)


def _pair(data: Mapping[str, Any], a: str, b: str, where: str) -> tuple[float, float] | None:
    if a not in data and b not in data:
        return None
    try:
        return (float(data[a]), float(data[b]))
    except (KeyError, TypeError, ValueError):
        raise MechanismError(f"{where}: needs both {a} and {b} as numbers") from None


def mechanism_from_graph(g: nx.Graph) -> Mechanism:
    """A validated :class:`Mechanism` from a link–joint graph.

    Reads the attributes of :func:`mechanism_to_graph`, and also the graph of
    :meth:`Mechanism.graph` (nodes ``("link", id)``, ``("joint", id)``) or any
    bipartite graph whose nodes carry ``bipartite`` 0 (links) and 1 (joints).
    """
    if g.is_directed() or g.is_multigraph():
        raise MechanismError("graph: must be a simple undirected graph (links and joints)")
    links: list[tuple[int, str, Any]] = []
    joints: list[tuple[int, str, Any]] = []
    kinds: dict[Any, tuple[str, str]] = {}
    for k, (node, data) in enumerate(g.nodes(data=True)):
        kinds[node] = _part(node, data)
        part, ident = kinds[node]
        (links if part == LINK else joints).append((int(data.get("index", k)), ident, node))
    links.sort(key=lambda t: t[0])
    joints.sort(key=lambda t: t[0])
    index = {node: k for k, (_, _, node) in enumerate(links)}
    frames = [ident for _, ident, node in links if _flag(g.nodes[node].get("frame", False))]
    if len(frames) > 1:
        raise MechanismError(f"graph: links {frames[0]!r} and {frames[1]!r} are both marked frame")
    out: list[Joint] = []
    drivers: list[str] = []
    for _, ident, node in joints:
        data = g.nodes[node]
        where = f"graph: joint {ident!r}"
        neighbours = list(g[node])
        for other in neighbours:
            if kinds[other][0] != LINK:
                raise MechanismError(f"{where} is joined to another joint, not to a link")
        neighbours.sort(key=lambda o: (int(g[node][o].get("position", 0)), index[o]))
        kind = str(data.get("type", "R")).upper()
        at = _pair(data, "x", "y", where)
        axis = _pair(data, "axis_x", "axis_y", where)
        out.append(Joint(ident, tuple(kinds[o][1] for o in neighbours), kind, at, axis))
        if _flag(data.get("driver", False)):
            drivers.append(ident)
    points: list[Point] = []
    if "points" in g.graph:
        try:
            for p in json.loads(g.graph["points"]):
                x, y = (float(v) for v in p["at"])
                points.append(Point(str(p["id"]), str(p["link"]), (x, y)))
        except (TypeError, ValueError, KeyError):
            raise MechanismError("graph: the 'points' attribute is not a list of points") from None
    extra: dict[str, Any] = {}
    if "extra" in g.graph:
        try:
            extra = json.loads(g.graph["extra"])
        except (TypeError, ValueError):
            raise MechanismError("graph: the 'extra' attribute is not JSON text") from None
        if not isinstance(extra, dict):
            raise MechanismError("graph: the 'extra' attribute must hold an object")
    gear_edges = [
        {"id": str(d.get("gear_id", f"g{k}")), "links": [kinds[u][1], kinds[v][1]],
         "type": str(d.get("gear_type", "external"))}
        for k, (u, v, d) in enumerate(g.edges(data=True))
        if d.get("pair") == "gear" and kinds[u][0] == kinds[v][0] == LINK
    ]  # fmt: skip
    if gear_edges and "gears" not in extra:  # a graph tool's file: the pairs from edges
        extra["gears"] = gear_edges
    m = Mechanism(
        links=tuple(ident for _, ident, _ in links),
        joints=tuple(out),
        frame=frames[0] if frames else None,
        drivers=tuple(drivers),
        name=str(g.graph.get("name", "")),
        points=tuple(points),
        extra=extra,
    )
    if "gears" in extra:
        read_gear_pairs(extra["gears"], m)
    return m


def mechanism_to_graphml(m: Mechanism) -> str:
    """GraphML text of the link–joint graph (see the module's attribute list)."""
    import networkx as nx

    return "\n".join(nx.generate_graphml(mechanism_to_graph(m))) + "\n"


def mechanism_from_graphml(text: str, source: str = "graphml") -> Mechanism:
    """A mechanism from GraphML text (written here or by a graph tool)."""
    import networkx as nx

    try:
        g = nx.parse_graphml(text)
    except Exception as exc:  # the XML parser's errors have no common base
        raise MechanismError(
            f"{source}: not valid GraphML ({exc.__class__.__name__}: {exc})"
        ) from None
    return mechanism_from_graph(g)


def mechanism_to_node_link(m: Mechanism) -> dict[str, Any]:
    """networkx's node-link object (``nodes``, ``edges``) of the link–joint graph."""
    import networkx as nx

    g = mechanism_to_graph(m)
    try:
        data: dict[str, Any] = nx.node_link_data(g, edges="edges")
    except TypeError:  # networkx < 3.4 names the keyword ``link``
        data = nx.node_link_data(g, link="edges")
    return data


def mechanism_from_node_link(data: Any, source: str = "node-link") -> Mechanism:
    """A mechanism from a node-link object (edges under ``edges`` or ``links``)."""
    import networkx as nx

    if not isinstance(data, Mapping) or "nodes" not in data:
        raise MechanismError(f"{source}: a node-link object needs 'nodes' and 'edges'")
    key = "edges" if "edges" in data else "links"
    if key not in data:
        raise MechanismError(f"{source}: a node-link object needs 'nodes' and 'edges'")
    try:
        try:
            g = nx.node_link_graph(dict(data), edges=key)
        except TypeError:  # networkx < 3.4 names the keyword ``link``
            g = nx.node_link_graph(dict(data), link=key)
    except (KeyError, TypeError, nx.NetworkXError) as exc:
        raise MechanismError(f"{source}: not a node-link graph ({exc})") from None
    return mechanism_from_graph(g)
