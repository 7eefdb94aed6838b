"""Thousands of joints between the same two links: a multiplicity, not a search problem.

Before: 3000 joints joining links 0 and 1 made ``analyze`` run past 120 s (nauty's
search over every permutation of the joints, for the canonical code and the loops),
deaf to SIGTERM; ``convert`` wrote a 20 000-joint file of this kind that ``analyze``
never finished.  Now parallel joints are counted as one with a multiplicity (exact:
checked against nauty on the whole graph and against the exhaustive drawing search),
and a long nauty run sits in a worker process that a signal stops at once.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pynauty
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.cli.main import main
from mjstruct.mechanism import Joint, Mechanism
from mjstruct.structure import loops
from mjstruct.structure.isomorphism import (
    QUOTIENT_VERTICES,
    Level,
    canonical_code,
    colour_classes,
    link_joint_lists,
    nauty_graph,
)
from mjstruct.structure.loops import loop_assortment
from project_paths import ROOT
from strategies import chains, relabelled


def _parallel(count: int) -> dict[str, object]:
    return {"frame": "0", "joints": [{"id": f"J{k}", "links": ["0", "1"]} for k in range(count)]}


def test_analyze_counts_3000_parallel_joints_as_a_multiplicity(tmp_path, capsys) -> None:
    path = tmp_path / "parallel.json"
    path.write_text(json.dumps(_parallel(3000)))
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    # two links, 3000 simple joints: K = p - n + 1, every loop two links (2999 inner + outer)
    assert (out["n"], out["K"], out["V"]) == (2, 2999, 0)
    assert out["loops"] == [2] * 3000
    assert out["canonical"].startswith("c2.3000-")


def test_convert_of_parallel_joints_then_analyze(tmp_path, capsys) -> None:
    # the reproducer had 20 000 (convert 3.5 s, analyze 1.8 s from the shell): 5000 here
    expr = tmp_path / "many.pmks"
    lines = ",\n".join("  J[R, P[0, 0], L[ground, link_1]]" for _ in range(5000))
    expr.write_text(f"M[\n{lines}\n]\n")
    out = tmp_path / "many.json"
    assert main(["convert", str(expr), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["analyze", str(out), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert (report["n"], report["K"], report["loops"][:3]) == (2, 4999, [2, 2, 2])


LEVELS_CHECKED: list[Level] = ["chain", "mechanism"]


def _full_certificate(m: Mechanism, level: str = "mechanism") -> bytes:
    """nauty on the whole graph, no quotient: the oracle (fast at these sizes)."""
    classes = colour_classes(m, level)
    cert: bytes = pynauty.certificate(nauty_graph(len(m.links), link_joint_lists(m), classes))
    return cert


@st.composite
def with_parallels(draw: st.DrawFn, big: bool = True) -> Mechanism:
    """A random chain with some of its joints repeated (parallel joints), and sometimes
    binary links in the same two joints; large enough for the quotient when ``big``."""
    base = draw(chains(max_links=7, max_multiplicity=3))
    joints = list(base.joints)
    links = list(base.links)
    copies = draw(st.lists(st.integers(0, 40 if big else 2), min_size=len(joints)))
    extra: list[Joint] = []
    for k, j in enumerate(joints):
        for c in range(copies[k] if k < len(copies) else 0):
            extra.append(Joint(f"{j.id}p{c}", j.links, j.kind))
    if draw(st.booleans()) and len(joints) >= 2:  # binary links between two joints
        a, b = joints[0], joints[1]
        for c in range(draw(st.integers(0, 30 if big else 2))):
            links.append(f"b{c}")
            extra.append(Joint(f"{a.id}b{c}", (a.links[0], f"b{c}"), a.kind))
            extra.append(Joint(f"{b.id}b{c}", (f"b{c}", b.links[0]), b.kind))
    drivers = draw(
        st.lists(st.sampled_from([j.id for j in joints + extra]), max_size=2, unique=True)
    )
    return Mechanism(tuple(links), tuple(joints + extra), frame="0", drivers=tuple(drivers))


@settings(max_examples=25, deadline=None)
@given(
    with_parallels(),
    with_parallels(),
    st.integers(0, 10**6),
    st.sampled_from(["chain", "mechanism"]),
)
def test_codes_with_parallel_joints_agree_with_nauty_on_the_whole_graph(a, b, seed, level) -> None:
    # relabelled: isomorphic, so equal codes; a against b: equal exactly when nauty on
    # the whole graphs says so
    assert canonical_code(relabelled(a, seed), "chain") == canonical_code(a, "chain")
    same = _full_certificate(a, level) == _full_certificate(b, level)
    sizes = [len(c) for c in colour_classes(a, level)] == [
        len(c) for c in colour_classes(b, level)
    ]
    assert (canonical_code(a, level) == canonical_code(b, level)) == (same and sizes)  # type: ignore[arg-type]


@settings(max_examples=40, deadline=None)
@given(with_parallels(big=False))
def test_loops_with_parallel_joints_agree_with_the_exhaustive_search(m) -> None:
    try:
        exact = loops._minimal_faces(m.adjacency)  # every drawing of the whole graph
    except loops._TooMany:
        return
    got = loop_assortment(m)
    assert (got is None) == (exact is None)
    if got is not None:
        assert got.sizes == exact and got.rule == "minimal"


def test_the_quotient_applies_only_to_large_graphs() -> None:
    # small chains keep the codes they always had (the atlases' and catalogs')
    small = Mechanism.build([(f"J{k}", [0, 1]) for k in range(3)])
    big = Mechanism.build([(f"J{k}", [0, 1]) for k in range(QUOTIENT_VERTICES)])
    assert canonical_code(small) == "c2.3-" + canonical_code(small).split("-")[1]
    assert canonical_code(small).split("-")[1] != canonical_code(big).split("-")[1]


@pytest.mark.parametrize(
    ("signum", "status", "line"),
    [(signal.SIGTERM, 143, "mjstruct: terminated"), (signal.SIGINT, 130, "mjstruct: interrupted")],
)
def test_a_signal_stops_a_long_nauty_run_at_once(tmp_path, signum, status, line) -> None:
    # 1500 parallel two-joint paths between links 0 and 1: no twins to merge, and
    # nauty's search takes about a minute inside C (measured 14 s for 1000 paths)
    n = 1500
    joints = [{"id": f"A{k}", "links": ["0", f"m{k}"]} for k in range(n)]
    joints += [{"id": f"B{k}", "links": [f"m{k}", "1"]} for k in range(n)]
    path = tmp_path / "paths.json"
    path.write_text(json.dumps({"frame": "0", "joints": joints}))
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "mjstruct", "analyze", str(path), "--json"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=env,
    )
    try:
        time.sleep(2.0)  # start-up and the structural formulas: then inside nauty
        assert proc.poll() is None
        sent = time.monotonic()
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=10)
        waited = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == status and err.decode() == line + "\n"
    assert waited < 1.5, waited
    # no worker left behind
    assert not subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True).stdout


def test_a_large_graph_gets_the_same_code_from_the_worker(monkeypatch) -> None:
    from mjstruct.structure import isomorphism

    ring = Mechanism.build([(f"J{k}", [k, (k + 1) % 1100]) for k in range(1100)])
    assert len(ring.links) + len(ring.joints) >= isomorphism.WORKER_VERTICES
    started = []
    real = isomorphism._in_worker
    monkeypatch.setattr(isomorphism, "_in_worker", lambda a: started.append(1) or real(a))
    from_worker = canonical_code(ring)
    assert started == [1]
    monkeypatch.setattr(isomorphism, "WORKER_VERTICES", 10**9)
    assert canonical_code(ring) == from_worker and len(started) == 1
    assert loop_assortment(ring) is not None and loop_assortment(ring).sizes == (1100, 1100)
