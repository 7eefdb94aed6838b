"""Atlas enumeration: published counts, no duplicates (VF2), admissibility (brute force),
completeness against independent brute-force enumerations on small cases."""

from __future__ import annotations

import itertools
import json
import os
import random
import signal
import subprocess
import sys
import time

import networkx as nx
import pytest
from networkx.algorithms.isomorphism import GraphMatcher

from mjstruct.cli.main import main
from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import canonical_code
from mjstruct.synthesis.admissibility import (
    is_admissible,
    is_fractionated,
    rigid_subchain,
    subchain_mobility,
)
from mjstruct.synthesis.assur_atlas import assur_atlas
from mjstruct.synthesis.atlas import atlas
from mjstruct.synthesis.catalog import read_catalog

# Published counts of non-fractionated simple-joint chains without rigid sub-chains
# (Mruthyunjaya; Tsai, "Mechanism design: enumeration of kinematic structures").
PUBLISHED = [(1, 4, 1), (1, 6, 2), (1, 8, 16), (1, 10, 230), (2, 5, 1), (2, 7, 3), (2, 9, 35)]


@pytest.mark.parametrize(("F", "n", "count"), PUBLISHED)
def test_published_simple_joint_counts(F: int, n: int, count: int) -> None:
    assert atlas(F, n).count == count


def test_twelve_links_with_two_workers() -> None:
    a = atlas(1, 12, workers=2)
    assert a.count == 6856
    assert len({c.canonical for c in a.chains}) == a.count


def test_ten_links_nonplanar_are_kept_and_flagged() -> None:
    a = atlas(1, 10)
    nonplanar = [c for c in a.chains if not c.planar]
    assert len(nonplanar) == 11
    for c in nonplanar:
        assert not nx.check_planarity(c.mechanism().graph())[0]


@pytest.mark.parametrize(("F", "n", "count"), [(2, 7, 4), (2, 9, 40)])
def test_fractionated_counts(F: int, n: int, count: int) -> None:
    """With fractionated chains the published 2-DOF totals are 4 and 40."""
    a = atlas(F, n, fractionated=True)
    assert a.count == count
    assert sum(c.fractionated for c in a.chains) == count - atlas(F, n).count


def test_worker_count_does_not_change_output() -> None:
    one = atlas(1, 10, mj=True)
    two = atlas(1, 10, mj=True, workers=2)
    assert [c.to_dict() for c in one.chains] == [c.to_dict() for c in two.chains]


def _vf2_duplicates(chains: list) -> int:
    graphs = [c.mechanism().graph() for c in chains]
    dup = 0
    for ga, gb in itertools.combinations(graphs, 2):
        if sorted(d for _, d in ga.degree()) != sorted(d for _, d in gb.degree()):
            continue
        gm = GraphMatcher(ga, gb, node_match=lambda x, y: x["bipartite"] == y["bipartite"])
        dup += gm.is_isomorphic()
    return dup


SMALL = [(1, 6, True, False), (1, 8, True, False), (2, 7, True, True), (2, 9, False, True)]


@pytest.mark.parametrize(("F", "n", "mj", "frac"), SMALL)
def test_small_atlases_exact(F: int, n: int, mj: bool, frac: bool) -> None:
    a = atlas(F, n, mj=mj, fractionated=frac)
    assert _vf2_duplicates(a.chains) == 0
    for c in a.chains:
        m = c.mechanism()
        assert is_admissible(m), c
        assert canonical_code(m, "chain") == c.canonical
        assert is_fractionated(m) == c.fractionated
        assert m.n == n and (n - 1 - F) // 2 == c.K
        assert mj or c.V == 0


def test_mj_atlas_extends_the_simple_joint_one() -> None:
    sj = atlas(2, 9)
    mj = atlas(2, 9, mj=True)
    assert [c.canonical for c in mj.chains[: sj.count]] == [c.canonical for c in sj.chains]
    assert all(c.V > 0 for c in mj.chains[sj.count :])
    # j <= K for every joint, V <= 2(K - 1)
    for c in mj.chains:
        assert max(len(j) - 1 for j in c.joints) <= c.K
        assert c.V <= 2 * (c.K - 1)


def _brute_force_codes(F: int, n: int, fractionated: bool) -> set[str]:
    """Every set of joints (any multiplicity) on n links, filtered and deduplicated."""
    K = (n - 1 - F) // 2
    budget = n - 1 + K  # Σ (m - 1) = p
    cands = [s for r in range(2, n + 1) for s in itertools.combinations(range(n), r)]
    codes: set[str] = set()

    def rec(start: int, left: int, chosen: list, pairs: frozenset, deg: list[int]) -> None:
        if left == 0:
            if min(deg) < 2:
                return
            try:
                m = Mechanism.build([(f"J{k}", list(s)) for k, s in enumerate(chosen)])
            except Exception:  # disconnected
                return
            if is_admissible(m) and (fractionated or not is_fractionated(m)):
                codes.add(canonical_code(m))
            return
        for k in range(start, len(cands)):
            s = cands[k]
            if not chosen and 0 not in s:
                break
            ps = frozenset(itertools.combinations(s, 2))
            if len(s) - 1 > left or ps & pairs:  # two links sharing two joints: rigid
                continue
            for x in s:
                deg[x] += 1
            chosen.append(s)
            rec(k + 1, left - len(s) + 1, chosen, pairs | ps, deg)
            chosen.pop()
            for x in s:
                deg[x] -= 1

    rec(0, budget, [], frozenset(), [0] * n)
    return codes


@pytest.mark.parametrize(("F", "n", "frac"), [(1, 4, True), (2, 5, True), (1, 6, True)])
def test_complete_against_brute_force_with_mj(F: int, n: int, frac: bool) -> None:
    expected = _brute_force_codes(F, n, frac)
    got = {c.canonical for c in atlas(F, n, mj=True, fractionated=frac).chains}
    assert got == expected


def test_complete_against_networkx_graph_atlas() -> None:
    """Simple-joint chains up to 7 links from networkx's atlas of all small graphs."""
    expected: dict[tuple[int, int, bool], set[str]] = {}
    for g in nx.graph_atlas_g()[1:]:
        n = g.number_of_nodes()
        F = 3 * (n - 1) - 2 * g.number_of_edges()
        if n < 4 or F < 1 or not nx.is_connected(g) or min(d for _, d in g.degree()) < 2:
            continue
        m = Mechanism.build([(f"J{k}", [u, v]) for k, (u, v) in enumerate(g.edges)])
        if is_admissible(m):
            for frac in (False, True):
                if frac or not is_fractionated(m):
                    expected.setdefault((F, n, frac), set()).add(canonical_code(m))
    assert expected, "the graph atlas gave nothing"
    for (F, n, frac), codes in expected.items():
        got = {c.canonical for c in atlas(F, n, fractionated=frac).chains}
        assert got == codes, (F, n, frac)


def test_rigid_subchain_brute_force_reference() -> None:
    # two four-bar loops sharing a link pair (links 0, 1 share joints a and e): rigid pair
    m = Mechanism.build(
        [("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0]), ("e", [0, 1, 4])]
    )
    s = rigid_subchain(m)
    assert s is not None and subchain_mobility(m, set(s)) <= 0
    assert set(s) == {"0", "1"}


def test_cli_atlas_json_contract(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--dof", "1", "--links", "6", "--mj", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["count"] == len(out["chains"]) == 4
    names = {c["name"] for c in out["chains"]}
    assert {"Watt six-bar", "Stephenson six-bar"} <= names
    for c in out["chains"]:
        assert {"canonical", "LA", "MJA", "planar", "joints", "id"} <= set(c)
        m = Mechanism.build([(f"J{k}", js) for k, js in enumerate(c["joints"])])
        assert canonical_code(m) == c["canonical"]


def test_cli_atlas_summary_makes_no_row_per_chain(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The text summary counts the chains without a dictionary per chain (an atlas
    holds hundreds of thousands: they were most of the command's memory); --list and
    --json make them, and the summary's counts are the listed chains'."""
    from mjstruct.synthesis.atlas import Chain

    made = []
    real = Chain.to_dict
    monkeypatch.setattr(Chain, "to_dict", lambda c: made.append(c) or real(c))
    assert main(["atlas", "--dof", "1", "--links", "8", "--mj"]) == 0
    summary = capsys.readouterr().out.splitlines()
    assert made == []
    assert main(["atlas", "--dof", "1", "--links", "8", "--mj", "--list"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert len(made) == int(summary[0].split(": ")[1].split()[0]) > 0
    assert listed[: len(summary)] == summary


def test_cli_atlas_bad_input(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--dof", "1", "--links", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--links" in err
    assert main(["atlas", "--dof", "1", "--links", "6", "--workers", "0"]) == 2


def test_cli_atlas_odd_size_is_empty(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--dof", "1", "--links", "7", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["count"] == 0


def test_assur_atlas_small_groups() -> None:
    from mjstruct.synthesis.assur_atlas import assur_atlas

    assert [(g.klass, g.order) for g in assur_atlas(2)] == [(2, 2)]  # the dyad
    # triad (class III, 3 external pairs) and the four-link contour group (class IV)
    assert sorted((g.klass, g.order) for g in assur_atlas(4)) == [(3, 3), (4, 2)]


def test_assur_atlas_groups_are_exact_and_distinct() -> None:
    from mjstruct.synthesis.assur_atlas import assur_atlas

    groups = assur_atlas(6)
    assert len({g.canonical for g in groups}) == len(groups)
    marked = []
    for g in groups:
        n, p, e = g.n, len(g.joints), g.order
        assert 3 * n == 2 * (p + e)
        assert len(set(g.external)) == e  # at most one external pair per link
        # brute force: every proper subset of links keeps mobility >= 1 w.r.t. the ground
        for r in range(1, n):
            for s in itertools.combinations(range(n), r):
                ps = sum(1 for a, b in g.joints if a in s and b in s)
                es = sum(1 for x in g.external if x in s)
                assert 3 * len(s) - 2 * (ps + es) >= 1
                if r >= 2:
                    assert 3 * (r - 1) - 2 * ps >= 1
        h = nx.Graph([tuple(j) for j in g.joints] + [(x, "G") for x in g.external])
        nx.set_node_attributes(h, {v: v == "G" for v in h}, "ground")
        marked.append(h)
    for a, b in itertools.combinations(marked, 2):
        assert not nx.is_isomorphic(a, b, node_match=lambda x, y: x["ground"] == y["ground"])


def test_cli_atlas_assur_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--assur", "--links", "4", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["count"] == 2
    assert {g["class"] for g in out["groups"]} == {3, 4}


def test_progress_bar_only_when_enabled() -> None:
    import io

    from mjstruct.synthesis.parallel import ProgressBar

    quiet, loud = io.StringIO(), io.StringIO()
    atlas(1, 8, progress=ProgressBar("x", enabled=False, stream=quiet))
    atlas(1, 8, progress=ProgressBar("x", enabled=True, stream=loud))
    assert quiet.getvalue() == ""
    text = loud.getvalue()
    assert text.endswith("\n") and "5/5 tasks" in text  # K = 3: five branch-vertex multisets


def test_cli_atlas_json_is_quiet_on_stderr(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["atlas", "--links", "8", "--json"]) == 0
    assert capsys.readouterr().err == ""


def _random_chain(rng: random.Random, n: int, F: int) -> list[list[int]] | None:
    """A random link–joint pairing with a random admissible-looking assortment
    (configuration model); None when the pairing puts a link twice on a joint."""
    from mjstruct.synthesis.cells import link_assortments, mj_assortments

    K = (n - 1 - F) // 2
    V = rng.randrange(0, 2 * K - 1)
    mja = rng.choice(mj_assortments(K, V)) if V else ()
    la = rng.choice(link_assortments(K, V, F))
    degrees = [k + 2 for k, count in enumerate(la) for _ in range(count)]
    sizes = [k + 3 for k, count in enumerate(mja) for _ in range(count)]
    sizes += [2] * (n - 1 + K - sum(m - 1 for m in sizes))
    stubs = [i for i, d in enumerate(degrees) for _ in range(d)]
    assert len(stubs) == sum(sizes)
    rng.shuffle(stubs)
    joints, k = [], 0
    for m in sizes:
        joints.append(stubs[k : k + m])
        k += m
    return None if any(len(set(j)) < len(j) for j in joints) else joints


@pytest.mark.parametrize(("F", "n"), [(1, 8), (2, 9), (1, 10)])
def test_random_admissible_chains_are_in_the_atlas(F: int, n: int) -> None:
    """Completeness by sampling: every admissible chain drawn at random is listed."""
    from mjstruct.errors import MechanismError

    known = {c.canonical: c for c in atlas(F, n, mj=True, fractionated=True).chains}
    rng = random.Random(20261121 + n)
    hits = 0
    for _ in range(2500):
        joints = _random_chain(rng, n, F)
        if joints is None:
            continue
        try:
            m = Mechanism.build([(f"J{k}", j) for k, j in enumerate(joints)])
        except MechanismError:  # disconnected
            continue
        if not is_admissible(m):
            continue
        hits += 1
        code = canonical_code(m)
        assert code in known, joints
        assert known[code].fractionated == is_fractionated(m)
    assert hits >= 10


def test_fast_admissibility_equals_brute_force_per_distribution() -> None:
    """The contracted-graph test against the brute-force rule on every expanded chain."""
    from mjstruct.errors import MechanismError
    from mjstruct.synthesis.atlas import compositions, expand
    from mjstruct.synthesis.contracted import contracted_graphs, degree_sequences
    from mjstruct.synthesis.distributions import admissible_distributions, edge_minimum

    checked = 0
    for K, frac in ((2, True), (3, False), (3, True), (4, False)):
        for seq in degree_sequences(K, mj=True):
            for cg in contracted_graphs(seq, frac)[:4]:
                minima = [edge_minimum(cg, u, v) for u, v in cg.edges]
                n_branch = sum(c == "L" for c in cg.colours)
                for extra in range(4):
                    dist = compositions(extra + (n_branch == 0), minima)
                    if not len(dist):
                        continue
                    mask = admissible_distributions(cg, dist)
                    for row, ok in zip(dist.tolist(), mask.tolist(), strict=True):
                        _, joints = expand(cg, row)
                        try:
                            m = Mechanism.build([(f"J{k}", j) for k, j in enumerate(joints)])
                            truth = is_admissible(m)
                        except MechanismError:  # a link twice on one joint
                            truth = False
                        assert ok == truth, (cg, row)
                        checked += 1
    assert checked > 5000


# -- the size of a job, told before it starts ------------------------------------------


def test_estimates_from_smaller_sizes_are_within_a_factor_three():
    from mjstruct.synthesis.job_size import extrapolate_count

    sj = [(4, 1), (6, 2), (8, 16), (10, 230), (12, 6856)]
    mj = [(4, 1), (6, 4), (8, 60), (10, 2645), (12, 248203)]
    for series in (sj, mj):
        for k in (3, 4):
            guess = extrapolate_count(tuple(series[:k]), series[k][0], 2)
            assert guess is not None and 1 / 3 < guess / series[k][1] < 3


def test_estimates_are_exact_where_counted():
    from mjstruct.synthesis.job_size import assur_group_count_estimate, chain_count_estimate

    assert chain_count_estimate(1, 10) == len(atlas(1, 10).chains) == 230
    assert chain_count_estimate(2, 9, mj=True, fractionated=True) == len(read_catalog(2, 9))
    assert chain_count_estimate(1, 11) == chain_count_estimate(2, 4) == 0
    assert assur_group_count_estimate(6) == len(assur_atlas(6)) == 10


@pytest.mark.parametrize(
    "argv",
    [
        ["--links", "1000"],
        ["--links", "30"],
        ["--links", "100", "--mj"],
        ["--links", "300"],
        ["--links", "14", "--mj"],
        ["--assur", "--links", "1000"],
        ["--assur", "--links", "12"],
    ],
)
def test_cli_refuses_huge_jobs_with_their_size(capsys, argv):
    import time

    start = time.perf_counter()
    assert main(["atlas", *argv]) == 2
    assert time.perf_counter() - start < 5
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith("mjstruct atlas: --links: ")
    assert "expected, more than 1000000; pass --large" in captured.err


def test_large_flag_and_library_limit():
    from mjstruct.errors import MechanismError

    with pytest.raises(MechanismError, match=r"^limit: about 5\.0e\+07 chains for F = 1"):
        atlas(1, 14, mj=True)
    assert len(atlas(1, 8, limit=None).chains) == 16
    assert main(["atlas", "--links", "8", "--large", "--json"]) == 0


def test_workers_are_capped_at_the_core_count(monkeypatch):
    import multiprocessing
    import multiprocessing.pool

    from mjstruct.synthesis import parallel

    seen = []

    class Recorder(multiprocessing.pool.ThreadPool):
        def __init__(self, processes, initializer=None, initargs=()):
            seen.append(processes)
            super().__init__(1)

    monkeypatch.setattr(multiprocessing, "Pool", Recorder)
    monkeypatch.setattr(parallel, "core_count", lambda: 2)
    assert list(parallel.run_tasks(abs, [-1, -2, -3], workers=1000)) == [1, 2, 3]
    assert seen == [2]
    assert parallel.core_count() >= 1


def test_results_as_they_come_are_all_there() -> None:
    from mjstruct.synthesis.parallel import run_tasks

    tasks = list(range(-40, 0))
    for workers in (1, 2):
        got = list(run_tasks(abs, tasks, workers=workers, as_done=True))
        assert sorted(got) == list(range(1, 41))
        assert list(run_tasks(abs, tasks, workers=workers)) == [abs(t) for t in tasks]


def _children(pid: int) -> list[int]:
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as fh:
            return [int(x) for x in fh.read().split()]
    except (FileNotFoundError, ProcessLookupError):
        return []


def _running(pid: int) -> bool:
    """The process exists and is not a zombie (an ended process not yet reaped)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):
        return False


def _states(pids: list[int]) -> dict[int, str]:
    """Each process's command line and /proc status line, for a failure message."""
    out = {}
    for pid in pids:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                command = fh.read().replace(b"\0", b" ").decode(errors="replace")
            with open(f"/proc/{pid}/stat") as fh:
                out[pid] = f"{command.strip()} | {fh.read().strip()}"
        except (FileNotFoundError, ProcessLookupError):
            out[pid] = "gone"
    return out


def _wait_for_workers(job: subprocess.Popen[str], count: int) -> list[int]:
    """The job's child processes, once there are ``count`` (generous: the machine may
    be loaded)."""
    workers: list[int] = []
    deadline = time.monotonic() + 120
    while len(workers) < count and time.monotonic() < deadline and job.poll() is None:
        time.sleep(0.1)
        workers = _children(job.pid)
    assert len(workers) >= count, f"the pool did not start: {workers}, status {job.poll()}"
    return workers


def _end(job: subprocess.Popen[str], workers: list[int]) -> None:
    """This test's own processes, should the test fail."""
    if job.poll() is None:
        job.kill()
        job.wait()
    for pid in workers:
        if _running(pid):
            os.kill(pid, signal.SIGKILL)


def _gone(workers: list[int], seconds: float) -> list[int]:
    """The workers still running after waiting up to ``seconds`` for them to end."""
    deadline = time.monotonic() + seconds
    while any(map(_running, workers)) and time.monotonic() < deadline:
        time.sleep(0.1)
    return [pid for pid in workers if _running(pid)]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigterm_stops_the_workers_too() -> None:
    """SIGTERM once both workers exist: status 143, one line, no worker left."""
    if parallel_cores() < 2:
        pytest.skip("one core: no worker processes to leave behind")
    job = subprocess.Popen(
        [sys.executable, "-m", "mjstruct", "atlas", "--links", "12", "--mj", "--workers", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    workers: list[int] = []
    try:
        workers = _wait_for_workers(job, 2)
        job.send_signal(signal.SIGTERM)
        _, err = job.communicate(timeout=120)
        assert job.returncode == 143, (job.returncode, err)
        assert err.strip().endswith("mjstruct: terminated"), err
        assert _gone(workers, 60) == [], f"a worker outlived the parent: {_states(workers)}"
    finally:
        _end(job, workers)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG")
def test_workers_end_with_a_killed_parent() -> None:
    """SIGKILL leaves the parent no cleanup: the workers, each in a 300 s task, end
    anyway (the kernel kills them with their parent)."""
    if parallel_cores() < 2:
        pytest.skip("one core: no worker processes")
    script = (
        "import time\n"
        "from mjstruct.synthesis.parallel import run_tasks\n"
        "list(run_tasks(time.sleep, [300, 300], workers=2))\n"
    )
    job = subprocess.Popen([sys.executable, "-c", script], text=True)
    workers: list[int] = []
    try:
        workers = _wait_for_workers(job, 2)
        job.kill()
        job.wait(timeout=120)
        assert _gone(workers, 60) == [], f"a worker outlived the parent: {_states(workers)}"
    finally:
        _end(job, workers)


def parallel_cores() -> int:
    from mjstruct.synthesis.parallel import core_count

    return core_count()


def test_python_dash_m_runs_the_command():
    import subprocess
    import sys

    ok = subprocess.run(
        [sys.executable, "-m", "mjstruct", "--version"], capture_output=True, text=True
    )
    assert ok.returncode == 0 and ok.stdout.startswith("mjstruct ")
    bad = subprocess.run(
        [sys.executable, "-m", "mjstruct", "analyze", "/dev/zero"], capture_output=True, text=True
    )
    assert bad.returncode == 2 and "not a regular file" in bad.stderr


# -- the fast pipeline against its references ------------------------------------------


def test_ten_link_atlas_with_mjs_equals_the_shipped_catalog() -> None:
    """Every field of the 2645 chains, in order, as the catalog (made by the former
    per-distribution enumeration) has them."""
    a = atlas(1, 10, mj=True, workers=2)
    fields = ("canonical", "n", "K", "V", "LA", "MJA", "planar", "fractionated", "joints")
    assert [{k: c.to_dict()[k] for k in fields} for c in a.chains] == [
        {k: r[k] for k in fields} for r in read_catalog(1, 10)
    ]


def test_atlas_chains_come_sorted() -> None:
    for F, n, mj in ((1, 10, True), (2, 9, True), (1, 12, False)):
        chains = atlas(F, n, mj=mj, fractionated=True).chains
        assert chains == sorted(chains, key=lambda c: c.sort_key())


def _small_contracted_graphs() -> list:
    from mjstruct.synthesis.contracted import contracted_graphs, degree_sequences

    return [
        (cg, frac)
        for K, frac in ((2, True), (3, True), (4, False))
        for seq in degree_sequences(K, mj=True)
        for cg in contracted_graphs(seq, frac)[:3]
    ]


def test_one_distribution_per_chain_and_none_missing() -> None:
    """chain_distributions against every composition tested and deduplicated by nauty
    certificates; with threshold 0 too (the Assur atlas's minimal rigid chains)."""
    from mjstruct.synthesis.atlas import compositions, expand
    from mjstruct.synthesis.canonical_chains import chain_code
    from mjstruct.synthesis.distributions import (
        admissible_distributions,
        chain_distributions,
        edge_minimum,
    )
    from mjstruct.synthesis.expansion import expand_rows

    checked = 0
    for cg, _ in _small_contracted_graphs():
        minima = [edge_minimum(cg, u, v) for u, v in cg.edges]
        n_branch = sum(c == "L" for c in cg.colours)
        for extra in range(5):
            binaries = extra + (n_branch == 0)
            for threshold in (1, 0):
                rows = compositions(binaries, minima)
                rows = rows[admissible_distributions(cg, rows, threshold)] if len(rows) else rows
                expected = {chain_code(*expand(cg, r))[1] for r in rows.tolist()}
                ordered, fast = chain_distributions(cg, binaries, threshold)
                assert sorted(ordered.edges) == sorted(cg.edges)
                chains = expand_rows(ordered, fast, binaries)
                got = [chain_code(chains.n, chains.joints(r))[1] for r in range(len(fast))]
                assert len(got) == len(set(got)) and set(got) == expected, (cg, binaries)
                for r, row in enumerate(fast.tolist()):  # the vectorised expansion
                    assert chains.joints(r) == expand(ordered, row)[1]
                checked += len(got)
    assert checked > 300


def test_orbit_minima_against_listing_each_orbit() -> None:
    import numpy as np

    from mjstruct.synthesis.distributions import orbit_minima

    rng = np.random.default_rng(7)
    ne = 5
    # the group generated by a 3-cycle on positions 0..2 and the swap of 3 and 4
    cycle, swap = (1, 2, 0, 3, 4), (0, 1, 2, 4, 3)
    group = {tuple(range(ne))}
    while True:
        grown = group | {tuple(g[i] for i in p) for p in group for g in (cycle, swap)}
        if grown == group:
            break
        group = grown
    perms = np.array(sorted(group))
    rows = rng.integers(0, 4, size=(300, ne))
    mask = orbit_minima(rows, perms, 3)
    for row, keep in zip(rows.tolist(), mask.tolist(), strict=True):
        images = []
        for p in group:
            image = [0] * ne
            for j, x in enumerate(row):
                image[p[j]] = x
            images.append(image)
        assert keep == (row == min(images))


def test_labelling_equals_pynauty_on_every_ten_link_chain() -> None:
    """Codes and canonical joints from one labelling per chain and arrays, against
    pynauty's certificate and canonical labelling of each chain."""
    from mjstruct.synthesis.atlas import canonical_chain
    from mjstruct.synthesis.contracted import contracted_graphs, degree_sequences
    from mjstruct.synthesis.distributions import distributions_of
    from mjstruct.synthesis.expansion import expand_rows, labelled_chains

    count = 0
    for seq in degree_sequences(4, mj=True)[::7]:
        binaries = 10 - sum(c == "L" for c, _ in seq)
        for cg, rows in distributions_of(contracted_graphs(seq, False), binaries):
            chains = expand_rows(cg, rows, binaries)
            fast = labelled_chains(chains)
            assert fast == [canonical_chain(10, chains.joints(r)) for r in range(len(rows))]
            count += len(fast)
    assert count > 200


def test_light_nauty_graphs_answer_as_pynauty_graphs() -> None:
    import random

    import pynauty

    from mjstruct.structure.isomorphism import nauty_graph
    from mjstruct.synthesis import nauty_calls

    rng = random.Random(3)
    for _ in range(200):
        n = rng.randint(2, 9)
        joints = [
            rng.sample(range(n), min(n, rng.choice((1, 2, 2, 3))))
            for _ in range(rng.randint(1, 12))
        ]
        p = len(joints)
        cut = rng.randint(0, n)
        colours = [range(cut), range(cut, n), range(n, n + p)]
        light = nauty_calls.light_graph(n, joints, colours)
        heavy = nauty_graph(n, joints, colours)
        assert nauty_calls.certificate(light) == pynauty.certificate(heavy)
        assert nauty_calls.canon_label(light) == pynauty.canon_label(heavy)
        assert nauty_calls.automorphism_generators(light) == pynauty.autgrp(heavy)[0]


def test_the_paused_steps_leave_no_reference_cycles() -> None:
    """Generation and labelling run with the cyclic collector paused; nothing they make
    may need it (a cycle holding arrays would keep them to the end of the run)."""
    import gc

    from mjstruct.synthesis.atlas import _task_chains, atlas_tasks
    from mjstruct.synthesis.contracted import contracted_graphs
    from mjstruct.synthesis.distributions import distributions_of
    from mjstruct.synthesis.expansion import expand_rows, labelled_chains

    tasks = atlas_tasks(1, 10, mj=True)[-12:]
    _task_chains(tasks[0])  # one-time set-up (threadpoolctl, libc)
    gc.collect()
    was = gc.isenabled()
    gc.disable()
    try:
        made = 0
        for sequence, n, _, fractionated in tasks:
            binaries = n - sum(c == "L" for c, _ in sequence)
            for cg, rows in distributions_of(contracted_graphs(sequence, fractionated), binaries):
                made += len(labelled_chains(expand_rows(cg, rows, binaries)))
        assert made > 100
        gc.set_debug(gc.DEBUG_SAVEALL)
        found = gc.collect()
        assert found == 0, sorted({type(x).__name__ for x in gc.garbage})
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        if was:
            gc.enable()
