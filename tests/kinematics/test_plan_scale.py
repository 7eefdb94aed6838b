"""The planner's cost on large mechanisms, and the shortcuts that keep it near linear
answering as the plain computations do (the plans themselves are unchanged)."""

from __future__ import annotations

import cmath
import random

import pytest

from mjstruct.kinematics import planner
from mjstruct.kinematics.geometry import diameter, first_close_pair, read_geometry
from mjstruct.kinematics.steps import Topology, base
from mjstruct.structure.drivers import driver_balance
from mjstruct.testing import shared_crank


def _planned(k: int):  # type: ignore[no-untyped-def]
    """The first trial's planning state for k four-bars on one crank."""
    m = shared_crank(k)
    drv = tuple(m.drivers)
    groups, _, _ = planner._groups_from(m, None, driver_balance(m, drv))
    return m, planner._run(m, read_geometry(m, drv), Topology(m, drv), m.frame, groups)


def test_planning_work_grows_linearly_with_the_links():
    # candidates queued and nodes the triangle counts touch, per link: the same at
    # 100 and 800 links (every dyad's base runs through the frame, across one
    # multiple joint of all the couplers)
    per_link = []
    for k in (50, 400):
        m, st = _planned(k)
        assert len(st.placed) == len(m.links)
        per_link.append((st.pushes + st.cluster.visits) / len(m.links))
    assert per_link[1] <= 1.1 * per_link[0]


def _random_cluster(rng: random.Random):  # type: ignore[no-untyped-def]
    links = [f"L{k}" for k in range(rng.randint(2, 14))]
    links_of = {}
    for k in range(rng.randint(2, 16)):
        links_of[f"J{k}"] = tuple(rng.sample(links, rng.choice([2, 2, 2, 3, 4][: len(links)])))
    revolute = {x: tuple(j for j, on in links_of.items() if x in on) for x in links}
    return links, links_of, revolute


@pytest.mark.parametrize("seed", range(40))
def test_trees_answer_as_the_search_does(monkeypatch, seed):
    # every source gets a tree at once: each answer, after each addition, against the
    # breadth-first search on the same cluster
    monkeypatch.setattr(base, "GROW_AFTER", 0)
    monkeypatch.setattr(base, "MAX_TREES", 100)
    rng = random.Random(seed)
    links, links_of, revolute = _random_cluster(rng)
    placed: set[str] = set()
    known: set[str] = set()
    cp = base.ClusterPaths(links_of, revolute, placed, known)
    order = [(True, x) for x in links] + [(False, j) for j in links_of]
    rng.shuffle(order)
    answered = 0
    for is_link, node in order:
        if is_link:
            placed.add(node)
            cp.link_placed(node)
        else:
            known.add(node)
            cp.joint_known(node)
        for _ in range(3):
            if not known:
                break
            a = rng.choice(sorted(known))
            targets = set(rng.sample(sorted(links_of), min(3, rng.randint(1, len(links_of)))))
            full = rng.random() < 0.5
            got = cp.distances(a, targets, full)
            if a not in targets:
                assert got == cp._search(a, targets, full)[0]
                answered += a in cp.trees
    assert answered


def test_a_large_hull_gives_the_pairwise_diameter_bit_for_bit():
    rng = random.Random(5)
    for n in (64, 65, 300, 1200):
        # points on a circle: many pairs within rounding of the largest distance
        pts = [cmath.exp(2j * cmath.pi * k / n) * (1 + 1e-15 * rng.random()) for k in range(n)]
        pts.append(complex(rng.random(), rng.random()))
        assert diameter(pts) == max(abs(a - b) for a in pts for b in pts)


@pytest.mark.parametrize("seed", range(30))
def test_close_centres_found_as_the_pairwise_scan_finds_them(seed):
    rng = random.Random(seed)
    zs = [complex(rng.uniform(-1, 1), rng.uniform(-1, 1)) for _ in range(rng.randint(2, 60))]
    for _ in range(rng.randint(0, 3)):  # a few centres within the tolerance of another
        zs.append(rng.choice(zs) + 1e-12 * complex(rng.random(), rng.random()))
    rng.shuffle(zs)
    ids = [f"J{k}" for k in range(len(zs))]
    centres = dict(zip(ids, zs, strict=True))
    tol = 2e-12
    first = next(
        (
            (a, b)
            for i, a in enumerate(ids)
            for b in ids[i + 1 :]
            if abs(centres[a] - centres[b]) <= tol
        ),
        None,
    )
    assert first_close_pair(ids, centres, tol) == first
