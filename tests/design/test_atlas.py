"""Type and dimensional synthesis: the atlas's candidates and a ranked run."""

from __future__ import annotations

import json

import networkx as nx
import pytest

from mjstruct.cli.main import main
from mjstruct.design.atlas import atlas_candidates, synthesize_atlas
from mjstruct.errors import MechanismError
from mjstruct.io import read_mechanism
from mjstruct.synthesis.atlas import atlas


def _coloured(m, driven, link):
    """The link-joint graph with frame, driver, driven link and the point's link marked
    (networkx)."""
    g = nx.Graph()
    for x in m.links:
        role = {m.frame: "frame", driven: "driven", link: "point"}.get(x, "link")
        g.add_node(("L", x), role=role)
    for j in m.joints:
        g.add_node(("J", j.id), role="driver" if j.id in m.drivers else "joint")
        for x in j.links:
            g.add_edge(("J", j.id), ("L", x))
    return g


@pytest.mark.parametrize(("links", "mj"), [(4, False), (6, False), (6, True)])
def test_candidates_are_the_classes_of_every_choice(links, mj):
    # oracle: every (frame, frame joint as driver, point link) of every chain, grouped
    # by networkx's isomorphism of the coloured graphs
    from mjstruct.mechanism import Mechanism

    classes: list[nx.Graph] = []
    match = nx.algorithms.isomorphism.categorical_node_match("role", None)
    for chain in atlas(1, links, mj=mj).chains:
        base = chain.mechanism()
        for frame in base.links:
            for j in base.joints:
                if frame not in j.links:
                    continue
                m = Mechanism.build([(x.id, x.links) for x in base.joints], frame=frame,
                                    drivers=[j.id])  # fmt: skip
                for driven in set(j.links) - {frame}:
                    for link in m.links:
                        if link in (frame, driven):
                            continue
                        g = _coloured(m, driven, link)
                        if not any(nx.is_isomorphic(g, h, node_match=match) for h in classes):
                            classes.append(g)
    got = atlas_candidates(links, mj)
    assert len(got) == len(classes)
    assert all(c.mechanism.joint(c.driver).links[0] == c.frame for c in got)
    assert all(c.link not in c.mechanism.joint(c.driver).links[:2] for c in got)


def test_atlas_ranks_every_four_bar_choice_and_writes_the_best(tmp_path, capsys):
    task = {"task": "path", "point": "P",
            "targets": [[0.5, 1.1], [0.3, 1.1], [0.1, 0.9], [0.0, 0.5], [0.1, 0.25],
                        [0.3, 0.4], [0.5, 0.7], [0.6, 1.0]],
            "solver": {"restarts": 1, "screen": 500, "local_starts": 2}}  # fmt: skip
    r = synthesize_atlas(task, links=4, mj=False, seed=1)
    objectives = [x.result.objective for x in r.ranked if x.result is not None]
    assert objectives == sorted(objectives) and len(r.ranked) == 2
    assert r.details["raced"] == 2  # both screened, then both searched in full
    path = tmp_path / "task.json"
    path.write_text(json.dumps(task))
    out = tmp_path / "best.json"
    assert main(["synthesize", str(path), "-o", str(out), "--atlas", "4", "--seed", "1",
                 "--json"]) == 0  # fmt: skip
    captured = capsys.readouterr()
    d = json.loads(captured.out)
    # no terminal: progress as plain lines, the last one whole
    assert "synthesize --atlas 4: 4/4 candidate searches" in captured.err
    assert [x["objective"] for x in d["atlas"]] == [x.result.objective for x in r.ranked]
    assert d["objective"] == r.ranked[0].result.objective
    assert read_mechanism(out).extra["synthesis"]["point"] == "P"


def test_atlas_refuses_keys_of_one_mechanism():
    with pytest.raises(MechanismError, match=r"^region: names joints of one mechanism"):
        synthesize_atlas({"task": "path", "point": "P", "targets": [[0, 0]],
                          "region": {"J0": [[0, 0], [1, 1]]}}, links=4)  # fmt: skip
    with pytest.raises(MechanismError, match=r"^targets\[0\]"):
        synthesize_atlas({"task": "path", "point": "P", "targets": [[0, "x"]]}, links=4)
