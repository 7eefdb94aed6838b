"""The atlas of one-DOF epicyclic gear trains against an independent brute force
(every labelled tree, every gear-edge set, every partition of the turning edges into
levels, exact Willis ranks with sympy, networkx isomorphism) and the published
counts; the command's text and JSON."""

from __future__ import annotations

import functools
import itertools
import json
from collections.abc import Iterator
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest
import sympy as sp

from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.gears.atlas import RATIO_SEED, egt_atlas, willis_determined


def _partitions(items: list[int]) -> itertools.chain[list[list[int]]]:
    def rec(xs: list[int]) -> Iterator[list[list[int]]]:
        if not xs:
            yield []
            return
        for p in rec(xs[1:]):
            yield [[xs[0]], *p]
            for i in range(len(p)):
                yield [*p[:i], [xs[0], *p[i]], *p[i + 1 :]]

    return itertools.chain(rec(items))


@functools.cache
def _willis_exact(n: int, meshes: tuple[tuple[int, int, int], ...]) -> bool:
    """Rank n - 2 and no two links alike, exactly, with distinct rational ratios."""
    ks = [Fraction(-(2 * r + 3), r + 2) if r % 2 else Fraction(3 * r + 5, 7) for r in range(n)]
    m = sp.zeros(len(meshes), n)
    for row, (a, b, c) in enumerate(meshes):
        k = sp.Rational(ks[row].numerator, ks[row].denominator)
        m[row, a] += 1
        m[row, b] += k
        m[row, c] -= 1 + k
    if m.rank() != n - 2:
        return False
    null = m.nullspace()
    return all(any(v[i] != v[j] for v in null) for i, j in itertools.combinations(range(n), 2))


def _brute(n: int) -> tuple[list[nx.Graph], list[nx.Graph]]:
    """Rotation and displacement graphs from scratch: labelled trees (Prüfer), gear
    edges among the other pairs, each partition of the tree edges into levels kept
    when every circuit's path is two runs of different levels and each level is the
    union of runs (no two levels merged without a circuit saying so)."""
    rot: list[nx.Graph] = []
    dis: list[nx.Graph] = []
    labelled: set[tuple[frozenset[tuple[int, int, int]], frozenset[frozenset[int]]]] = set()

    def add(found: list[nx.Graph], g: nx.Graph) -> None:
        # networkx's exact test, within buckets of equal Weisfeiler-Lehman hashes
        same = nx.algorithms.isomorphism.categorical_node_match("kind", None)
        edge = nx.algorithms.isomorphism.categorical_edge_match("kind", None)
        g.graph["wl"] = nx.weisfeiler_lehman_graph_hash(g, node_attr="kind", edge_attr="kind")
        bucket = [h for h in found if h.graph["wl"] == g.graph["wl"]]
        if not any(nx.is_isomorphic(g, h, node_match=same, edge_match=edge) for h in bucket):
            found.append(g)

    seqs = itertools.product(range(n), repeat=n - 2) if n > 2 else [()]
    for seq in seqs:
        tree = nx.from_prufer_sequence(list(seq)) if n > 2 else nx.path_graph(n)
        edges = [tuple(sorted(e)) for e in tree.edges()]
        others = [p for p in itertools.combinations(range(n), 2) if not tree.has_edge(*p)]
        path_of = {(a, b): nx.shortest_path(tree, a, b) for a, b in others}
        for gears in itertools.combinations(others, n - 2):
            paths = [path_of[g] for g in gears]
            for part in _partitions(list(range(len(edges)))):
                level = {edges[e]: i for i, block in enumerate(part) for e in block}
                meshes = []
                runs = nx.Graph()
                runs.add_nodes_from(edges)
                ok = True
                for p in paths:
                    seq_l = [level[tuple(sorted(p[i : i + 2]))] for i in range(len(p) - 1)]
                    changes = [i for i in range(1, len(seq_l)) if seq_l[i] != seq_l[i - 1]]
                    if len(changes) != 1:
                        ok = False
                        break
                    meshes.append((p[0], p[-1], p[changes[0]]))
                    for i in range(len(p) - 2):
                        if i + 1 != changes[0]:
                            runs.add_edge(
                                tuple(sorted(p[i : i + 2])), tuple(sorted(p[i + 1 : i + 3]))
                            )
                forced = {frozenset(c) for c in nx.connected_components(runs)}
                if not ok or forced != {frozenset(edges[e] for e in b) for b in part}:
                    continue
                if not _willis_exact(n, tuple(meshes)):
                    continue
                # the same labelled structure from another tree: nothing new
                mesh_set = frozenset((min(a, b), max(a, b), c) for a, b, c in meshes)
                axes = frozenset(frozenset(x for e in b for x in edges[e]) for b in part)
                if (mesh_set, axes) in labelled:
                    continue
                labelled.add((mesh_set, axes))
                g = nx.Graph()
                g.add_nodes_from(range(n), kind="link")
                for k, (a, b, c) in enumerate(meshes):
                    g.add_node(("m", k), kind="mesh")
                    g.add_edge(a, ("m", k), kind="gear")
                    g.add_edge(b, ("m", k), kind="gear")
                    g.add_edge(c, ("m", k), kind="carrier")
                add(rot, g.copy())
                for i, block in enumerate(part):
                    g.add_node(("axis", i), kind="axis")
                    for e in block:
                        for x in edges[e]:
                            g.add_edge(("axis", i), x, kind="axis")
                add(dis, g)
    return rot, dis


@pytest.mark.parametrize("n", [3, 4, 5])
def test_atlas_equals_brute_force(n: int) -> None:
    rot, dis = _brute(n)
    a = egt_atlas(n)
    assert (a.count, a.displacement_count) == (len(rot), len(dis))


def test_published_counts() -> None:
    # Buchsbaum & Freudenstein 1970 (4, 5 links); Yang et al. 2019 (6 links: 27
    # rotation, 81 displacement graphs); 7 links (152, 647) in docs/gears.md, too slow
    # for the suite (6 s)
    assert [(egt_atlas(n).count, egt_atlas(n).displacement_count) for n in (4, 5)] == [
        (2, 3),
        (6, 13),
    ]
    six = egt_atlas(6)
    assert (six.count, six.displacement_count) == (27, 81)
    codes = [t.canonical for t in six.trains]
    assert codes == sorted(set(codes))


def test_simple_planetary_is_in_the_atlas() -> None:
    # sun 1 and ring 2 coaxial with the carrier 0, planet 3 meshing both
    a = egt_atlas(4)
    star = [t for t in a.trains if len({g[2] for g in t.gears}) == 1]
    assert len(star) == 1
    (train,) = star
    planet = {x for g in train.gears for x in g[:2] if sum(x in h[:2] for h in train.gears) == 2}
    assert len(planet) == 1
    # the sun and the ring coaxial or not (an ordinary train): two displacement graphs
    assert sorted(len(d.axes) for d in train.displacements) == [2, 3]


def test_rule_3_refuses_rigid_and_idle_trains() -> None:
    rng = np.random.default_rng(RATIO_SEED)
    ratios = rng.uniform(0.3, 3.0, 5) * rng.choice([-1.0, 1.0], 5)
    # three gears 1, 2, 3 meshing in a triangle on carrier 0: locked; link 4 idle
    assert not willis_determined(5, ((1, 2), (2, 3), (1, 3)), (0, 0, 0), ratios)
    # the simple planetary: sun 1, ring 2, planet 3 on carrier 0
    assert willis_determined(4, ((1, 3), (2, 3)), (0, 0), ratios)
    # a 2-DOF differential with one gear edge fewer
    assert not willis_determined(5, ((1, 3), (2, 3)), (0, 0), ratios)


def test_workers_give_the_same_atlas() -> None:
    one = egt_atlas(6)
    calls: list[tuple[int, int]] = []
    two = egt_atlas(6, progress=lambda done, total: calls.append((done, total)), workers=2)
    assert two == one
    assert calls == [(k, 6) for k in range(7)]  # six links: six spanning trees


def test_progress_counts_trees() -> None:
    calls: list[tuple[int, int]] = []
    egt_atlas(6, progress=lambda done, total: calls.append((done, total)))
    # six links: six spanning trees
    assert calls == [(k, 6) for k in range(7)]


def test_bad_n() -> None:
    with pytest.raises(MechanismError, match=r"^n: "):
        egt_atlas(9)
    with pytest.raises(MechanismError, match=r"^n: "):
        egt_atlas(2)


def test_cli_gear_atlas(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--gears", "--links", "5", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert (d["n"], d["count"], d["displacement_count"]) == (5, 6, 13)
    assert len(d["trains"]) == 6
    t = d["trains"][0]
    assert len(t["gears"]) == 3 and all(len(g) == 3 for g in t["gears"])
    assert all(len(x["turning"]) == 4 == len(x["levels"]) for x in t["displacements"])
    assert main(["atlas", "--gears", "--links", "5", "--list"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("one-DOF epicyclic gear trains, n = 5: 6 rotation graphs")
    assert out.count("egt-r5") == 6
    assert main(["atlas", "--gears", "--links", "9"]) == 2
    assert capsys.readouterr().err.startswith("mjstruct atlas: --links: ")
    for extra in (["--assur"], ["--mj"], ["--dof", "2"], ["--draw", "x.pdf"]):
        assert main(["atlas", "--gears", "--links", "5", *extra]) == 2
        err = capsys.readouterr().err
        assert (
            err.startswith(f"mjstruct atlas: {extra[0]}: not with --gears")
            and "\n" not in err[:-1]
        )


def test_displacements_are_numbered_as_their_train() -> None:
    from mjstruct.gears.atlas import _code

    for t in egt_atlas(6).trains:
        for d in t.displacements:
            assert _code("d", 6, t.gears, d.axes) == d.canonical
            tree = nx.Graph(d.turning)
            assert nx.is_tree(tree) and tree.number_of_nodes() == 6
            assert all(
                set(e) <= set(d.axes[lv]) for e, lv in zip(d.turning, d.levels, strict=True)
            )
            for a, b, c in t.gears:
                on = [{x, c} <= set(axis) for axis in d.axes for x in (a, b)]
                assert sum(on) == 2  # a and b each on one axis with the carrier
                assert not any({a, b} <= set(axis) for axis in d.axes)


def test_atlas_does_not_depend_on_the_generic_ratios(monkeypatch: pytest.MonkeyPatch) -> None:
    import mjstruct.gears.atlas as module

    before = [(t.canonical, [d.canonical for d in t.displacements]) for t in egt_atlas(6).trains]
    monkeypatch.setattr(module, "RATIO_SEED", 2026)
    after = [(t.canonical, [d.canonical for d in t.displacements]) for t in egt_atlas(6).trains]
    assert after == before
