"""Thousands of joints between the same two links: a multiplicity, not a search problem.

Before: 3000 joints joining links 0 and 1 made ``analyze`` run past 120 s (nauty's
search over every permutation of the joints, for the canonical code and the loops),
deaf to SIGTERM; ``convert`` wrote a 20 000-joint file of this kind that ``analyze``
never finished.  Now parallel joints are counted as one with a multiplicity (exact:
checked against nauty on the whole graph and against the exhaustive drawing search),
and a long nauty run sits in a worker process that a signal stops at once.  Parallel
paths (k binary links each joining links 0 and 1 through two joints; any chains of
degree-two vertices with the same ends) are a multiplicity too: 1500 of them took nauty
about a minute.
"""

from __future__ import annotations

import itertools
import json
import os
import random
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

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


def _paths(count: int, kind_of_last: str = "R") -> dict[str, object]:
    joints = [{"id": f"A{k}", "links": ["0", f"m{k}"]} for k in range(count)]
    joints += [{"id": f"B{k}", "links": [f"m{k}", "1"]} for k in range(count)]
    joints[-1]["kind"] = kind_of_last
    return {"frame": "0", "joints": joints}


@pytest.mark.parametrize("count", [1500, 5000])
def test_analyze_counts_parallel_paths_as_a_multiplicity(tmp_path, capsys, count) -> None:
    # before: 1500 paths took nauty about a minute (three times: codes and loops)
    path = tmp_path / "paths.json"
    path.write_text(json.dumps(_paths(count)))
    assert main(["analyze", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["n"], out["K"], out["p"]) == (count + 2, count - 1, 2 * count)
    # side by side: every loop is links 0, m_i, 1, m_j (the outer one too)
    assert out["loops"] == [4] * count and out["loops_rule"] == "minimal"
    m = Mechanism.build(
        [(j["id"], j["links"], j.get("kind", "R")) for j in _paths(count)["joints"]],  # type: ignore[attr-defined]
        frame="0",
    )
    assert canonical_code(m) == out["canonical"]
    assert canonical_code(m, "mechanism") == out["canonical_mechanism"]
    # the same mechanism written otherwise has the same code; one prismatic joint among
    # the paths' joints changes the mechanism's code, not the chain's
    assert canonical_code(_shuffled(m, seed=count), "mechanism") == out["canonical_mechanism"]
    with_p = Mechanism.build(
        [(j["id"], j["links"], j.get("kind", "R")) for j in _paths(count, "P")["joints"]],  # type: ignore[attr-defined]
        frame="0",
    )
    assert canonical_code(with_p) == out["canonical"]
    assert canonical_code(with_p, "mechanism") != out["canonical_mechanism"]


def _shuffled(m: Mechanism, seed: int) -> Mechanism:
    """``m`` with new ids, its links and joints in another order (frame and drivers
    kept): isomorphic at every level."""
    rng = random.Random(seed)
    new = {x: f"L{k}" for k, x in enumerate(rng.sample(list(m.links), len(m.links)))}
    joints = [
        Joint(f"Q{j.id}", tuple(rng.sample([new[x] for x in j.links], len(j.links))), j.kind)
        for j in m.joints
    ]
    rng.shuffle(joints)
    links = [new[x] for x in m.links]
    rng.shuffle(links)
    return Mechanism(
        tuple(links),
        tuple(joints),
        frame=None if m.frame is None else new[m.frame],
        drivers=tuple(f"Q{d}" for d in m.drivers),
    )


Bundle = tuple[str, str, list[str], int]


@st.composite
def bundled(draw: st.DrawFn, big: bool = True) -> tuple[Mechanism, list[Bundle]]:
    """A random chain and bundles of parallel chains to add to it: each bundle is
    ``copies`` paths of binary links between two of its links (the same link for a
    cycle through it), with the kinds of the path's joints."""
    # small: few enough drawings for the exhaustive search, bundles of two to four
    base = draw(chains(max_links=6, max_multiplicity=3) if big else chains(4, 2))
    specs: list[Bundle] = []
    for _ in range(draw(st.integers(1, 3 if big else 2))):
        u, v = draw(st.sampled_from(base.links)), draw(st.sampled_from(base.links))
        length = draw(st.integers(1, 3))  # binary links along the path
        kinds = draw(st.lists(st.sampled_from("RRP"), min_size=length + 1, max_size=length + 1))
        specs.append((u, v, kinds, draw(st.integers(0, 40) if big else st.integers(2, 4))))
    return base, specs


def _with_bundles(
    base: Mechanism, specs: list[Bundle], odd: tuple[int, int, int] | None = None
) -> Mechanism:
    """``base`` with the bundles' paths; ``odd`` = (bundle, joint, path) flips the kind
    of that joint of that path of the bundle."""
    links, joints = list(base.links), list(base.joints)
    for b, (u, v, kinds, copies) in enumerate(specs):
        for c in range(copies):
            names = [f"x{b}_{c}_{i}" for i in range(len(kinds) - 1)]
            links += names
            path = [u, *names, v]
            for i, (x, y) in enumerate(itertools.pairwise(path)):
                kind = kinds[i]
                if odd == (b, i, c):
                    kind = "P" if kind == "R" else "R"
                joints.append(Joint(f"Y{b}_{c}_{i}", (x, y), kind))
    return Mechanism(tuple(links), tuple(joints), frame="0", drivers=base.drivers)


@settings(max_examples=50, deadline=None)
@given(bundled(), st.data(), st.sampled_from(["chain", "kinds", "mechanism"]))
def test_codes_with_parallel_chains_agree_with_nauty_on_the_whole_graph(spec, data, level):
    # a and b: the same chain written otherwise, one of its paths with a joint of the
    # other kind (in a, in b: the same joint of another path, or another joint), one
    # path fewer in b, or one moved to another bundle of paths as long (same counts)
    base, specs = spec
    pick = data.draw(st.integers(0, len(specs) - 1))
    u, v, kinds, copies = specs[pick]
    odd_a = odd_b = None
    change = data.draw(st.sampled_from(["none", "fewer", "kind", "move"]))
    if change == "kind" and copies:
        odd_a = (pick, data.draw(st.integers(0, len(kinds) - 1)), 0)
        odd_b = (pick, data.draw(st.integers(0, len(kinds) - 1)), copies - 1)
    b_specs = list(specs)
    if change in ("fewer", "move") and copies:
        b_specs[pick] = (u, v, kinds, copies - 1)
    if change == "move":  # the path to a bundle of the same length: as many links
        to = data.draw(st.integers(0, len(specs) - 1))
        if len(specs[to][2]) == len(kinds):
            x, y, other_kinds, n = b_specs[to]
            b_specs[to] = (x, y, other_kinds, n + 1)
        else:
            b_specs[pick] = specs[pick]
    a = _with_bundles(base, specs, odd_a)
    b = _shuffled(_with_bundles(base, b_specs, odd_b), data.draw(st.integers()))
    same = _codes_agree_with_nauty_on_the_whole_graph(a, b, level)
    assert same or change != "none"


@settings(max_examples=80, deadline=None)
@given(bundled(big=False))
def test_loops_with_parallel_chains_agree_with_the_exhaustive_search(spec) -> None:
    _loops_agree_with_the_exhaustive_search(_with_bundles(*spec))


def _loops_agree_with_the_exhaustive_search(m: Mechanism) -> None:
    try:
        exact = loops._minimal_faces(m.adjacency)  # every drawing of the whole graph
    except loops._TooMany:
        return
    got = loop_assortment(m)
    assert (got is None) == (exact is None)
    if got is not None:
        assert got.sizes == exact and got.rule == "minimal"


LEVELS_CHECKED: list[Level] = ["chain", "mechanism"]


def _full_certificate(m: Mechanism, level: str = "mechanism") -> bytes:
    """nauty on the whole graph, no quotient: the oracle (fast at these sizes)."""
    classes = colour_classes(m, level)
    cert: bytes = pynauty.certificate(nauty_graph(len(m.links), link_joint_lists(m), classes))
    return cert


def _codes_agree_with_nauty_on_the_whole_graph(a: Mechanism, b: Mechanism, level: Level) -> bool:
    """Equal codes exactly when nauty on the whole graphs (and the colour classes' sizes)
    say the two are isomorphic; returns whether they are."""
    same = _full_certificate(a, level) == _full_certificate(b, level)
    sizes = [len(c) for c in colour_classes(a, level)] == [
        len(c) for c in colour_classes(b, level)
    ]
    assert (canonical_code(a, level) == canonical_code(b, level)) == (same and sizes)
    return same


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
    _codes_agree_with_nauty_on_the_whole_graph(a, b, level)


@settings(max_examples=40, deadline=None)
@given(with_parallels(big=False))
def test_loops_with_parallel_joints_agree_with_the_exhaustive_search(m) -> None:
    _loops_agree_with_the_exhaustive_search(m)


def test_the_quotient_applies_only_to_large_graphs() -> None:
    # small chains keep the codes they always had (the atlases' and catalogs')
    small = Mechanism.build([(f"J{k}", [0, 1]) for k in range(3)])
    big = Mechanism.build([(f"J{k}", [0, 1]) for k in range(QUOTIENT_VERTICES)])
    assert canonical_code(small) == "c2.3-" + canonical_code(small).split("-")[1]
    assert canonical_code(small).split("-")[1] != canonical_code(big).split("-")[1]


def _blocks(count: int) -> dict[str, object]:
    """``count`` triangles-with-a-tail at link 0 (links a, b, c; joints 0a, ab, b0, ac,
    c0): no twins, no parallel chains (each block's chains end at its own link a), and
    nauty's search over the blocks' permutations is cubic: 1000 blocks take minutes."""
    joints = []
    for i in range(count):
        a, b, c = f"a{i}", f"b{i}", f"c{i}"
        joints += [["0", a], [a, b], [b, "0"], [a, c], [c, "0"]]
    return {"frame": "0", "joints": [{"id": f"J{k}", "links": js} for k, js in enumerate(joints)]}


_ENV = dict(os.environ, PYTHONPATH=str(ROOT / "src"))


def _command(*argv: str, stdout: int = subprocess.PIPE) -> subprocess.Popen[bytes]:
    """``python -m mjstruct ARGV`` running from this checkout, its errors on a pipe."""
    return subprocess.Popen(
        [sys.executable, "-m", "mjstruct", *argv], stdout=stdout, stderr=subprocess.PIPE, env=_ENV
    )


def _children(pid: int) -> bytes:
    return subprocess.run(["pgrep", "-P", str(pid)], capture_output=True).stdout


def _cpu_seconds(pid: int) -> float:
    """CPU time used so far by ``pid``, its reaped children and its live children."""
    ticks = 0
    for p in [pid, *map(int, _children(pid).split())]:
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except FileNotFoundError:  # gone meanwhile
            continue
        ticks += sum(int(x) for x in fields[11:15])  # utime, stime, cutime, cstime
    return ticks / os.sysconf("SC_CLK_TCK")


class _AfterSignal:
    """CPU seconds a child spends after a signal (wall time says little on a loaded
    machine): the reaped child's total, from the rusage of the waited-for children,
    less what it had used when signalled."""

    def __init__(self, pid: int) -> None:
        self.start = _reaped_cpu() + _cpu_seconds(pid)

    def spent(self) -> float:
        return _reaped_cpu() - self.start


def _reaped_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


@pytest.mark.parametrize(
    ("signum", "status", "line"),
    [(signal.SIGTERM, 143, "mjstruct: terminated"), (signal.SIGINT, 130, "mjstruct: interrupted")],
)
def test_a_signal_stops_a_long_nauty_run_at_once(tmp_path, signum, status, line) -> None:
    path = tmp_path / "blocks.json"
    path.write_text(json.dumps(_blocks(1000)))
    proc = _command("analyze", str(path), "--json", "--no-loops", stdout=subprocess.DEVNULL)
    try:
        # whatever the load: signal once nauty runs in its worker (the long phase)
        deadline = time.monotonic() + 120
        while not _children(proc.pid):
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.02)
        sent, cpu = time.monotonic(), _AfterSignal(proc.pid)
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=30)
        waited, spent = time.monotonic() - sent, cpu.spent()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == status and err.decode() == line + "\n"
    assert spent < 1.0 and waited < 10, (spent, waited)
    # no worker left behind
    assert not subprocess.run(["pgrep", "-f", str(path)], capture_output=True).stdout


@pytest.mark.parametrize("delay", [0.0, 0.25, 0.5])
def test_sigterm_at_any_moment_stops_the_command(tmp_path, delay) -> None:
    # start-up, imports, reading, the structural formulas: wherever SIGTERM lands, the
    # command stops at once, with its one line (or, before the interpreter runs our
    # code, killed by the signal as any program is: no output either way)
    path = tmp_path / "paths.json"
    path.write_text(json.dumps(_paths(5000)))
    proc = _command("analyze", str(path), "--json")
    try:
        time.sleep(delay)
        sent, cpu = time.monotonic(), _AfterSignal(proc.pid)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
        waited, spent = time.monotonic() - sent, cpu.spent()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    if out:  # it had answered: the whole answer (a signal waits for the output's end)
        assert json.loads(out)["n"] == 5002
    if proc.returncode == 0:
        return
    assert (proc.returncode, err) in ((143, b"mjstruct: terminated\n"), (-signal.SIGTERM, b""))
    assert spent < 1.0 and waited < 10, (spent, waited)


def test_a_reader_that_stopped_reading_does_not_hold_sigterm() -> None:
    # the answer is written whole while the reader takes it; a reader that stopped must
    # not keep the command alive: SIGTERM acts within about a second
    four_bar = str(ROOT / "catalogs" / "examples" / "four-bar.json")
    proc = _command("kinematics", four_bar, "--frames", "20000", "--json")  # ~12 MB of JSON
    try:
        deadline = time.monotonic() + 120
        written = 0
        while written < 16384:  # the answer is being written; nothing reads it
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
            io_lines = Path(f"/proc/{proc.pid}/io").read_text().splitlines()
            written = int(next(x for x in io_lines if x.startswith("wchar:")).split()[1])
        sent = time.monotonic()
        proc.send_signal(signal.SIGTERM)
        status = proc.wait(timeout=30)
        waited = time.monotonic() - sent
        assert proc.stderr is not None
        err = proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for pipe in (proc.stdout, proc.stderr):
            if pipe is not None:
                pipe.close()
    assert status == 143 and err == b"mjstruct: terminated\n"
    assert waited < 10, waited


def test_ctrl_c_while_the_command_is_imported_is_one_line() -> None:
    # the import of the command, made to take the KeyboardInterrupt a Ctrl-C raises
    probe = (
        "import runpy, sys\n"
        "class Stop:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        "        if name == 'mjstruct.cli.main':\n"
        "            raise KeyboardInterrupt\n"
        "sys.meta_path.insert(0, Stop())\n"
        "runpy.run_module('mjstruct', run_name='__main__')\n"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, env=_ENV, timeout=60)
    assert (p.returncode, p.stderr, p.stdout) == (130, b"mjstruct: interrupted\n", b"")


def test_a_signal_while_the_parser_is_built_is_one_line(monkeypatch, capsys) -> None:
    from mjstruct.cli import main as cli_main

    def interrupted(command: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(cli_main, "build_parser", interrupted)
    assert main(["analyze", "x.json"]) == 130
    assert capsys.readouterr().err == "mjstruct: interrupted\n"


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
