"""Atlas enumeration: all non-isomorphic admissible chains with F DOF and n links.

Method (exact, no generate-and-test over labelled graphs):

1. K = (n - 1 - F) / 2 loops.  Each multiset of branch vertices (links with >= 3
   joints, and with ``mj`` multiple joints) with Σ (deg - 2) = 2(K - 1) is one
   independent *task*; it fixes [LA] (n2 follows from n) and [MJA].
2. Per task, the coloured contracted multigraphs with those degrees
   (:mod:`mjstruct.synthesis.contracted`); chains on different contracted graphs are
   never isomorphic.
3. Per contracted graph, every distribution of the n2 binary links over its edges;
   the admissibility rule is tested for all distributions at once with numpy on the
   contracted graph: a minimal rigid set of links consists of branch vertices W and
   whole edge paths, and its mobility is
   ``3|W_L| + 2|W_J| - 3 + Σ_edges in W (b_e - 2)`` (b_e binary links on the edge),
   so only the 2^|W| vertex sets need checking, not the 2^n link sets.
4. Admissible chains are deduplicated by their nauty certificate; the canonical code
   is the one :func:`mjstruct.structure.isomorphism.canonical_code` gives at the
   ``"chain"`` level.

Chains are sorted by (V, [MJA], [LA], canonical code), so the simple-joint atlas is a
prefix of the one with multiple joints and the order does not depend on the number of
workers.

References
----------
.. [1] B. D. McKay, A. Piperno, "Practical graph isomorphism, II", Journal of
   Symbolic Computation, vol. 60, pp. 94–112, 2014. [McKay & Piperno 2014] in
   docs/references.md.

Examples
--------
>>> [atlas(1, n).count for n in (4, 6, 8)]
[1, 2, 16]
>>> [atlas(2, n).count for n in (5, 7)]
[1, 3]
>>> atlas(1, 6).chains[0].LA
(4, 2)
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mjstruct.errors import MechanismError, expect_int
from mjstruct.mechanism import Mechanism
from mjstruct.synthesis.canonical_chains import canonical_chain
from mjstruct.synthesis.contracted import (
    ContractedGraph,
    Vertex,
    contracted_graphs,
    degree_sequences,
)
from mjstruct.synthesis.job_size import CHAIN_LIMIT, chain_count_estimate, check_size

Joints = tuple[tuple[int, ...], ...]


@dataclass(frozen=True, slots=True)
class Chain:
    """One chain of an atlas: links 0..n-1 in nauty's canonical order.

    ``joints`` lists, per joint, the links it joins (sorted; joints sorted too), so a
    script can rebuild the chain; ``LA`` = (n2, n3, ...), ``MJA`` = (ν2, ν3, ...).
    Slotted (no per-chain dictionary): an atlas holds hundreds of thousands.
    """

    canonical: str
    n: int
    joints: tuple[tuple[int, ...], ...]
    LA: tuple[int, ...]
    MJA: tuple[int, ...]
    V: int
    K: int
    F: int
    planar: bool
    fractionated: bool

    @property
    def cell(self) -> tuple[int, int]:
        """The synthesis cell (K, V)."""
        return (self.K, self.V)

    def sort_key(self) -> tuple[Any, ...]:
        return (self.V, self.MJA, self.LA, self.canonical)

    def mechanism(self, name: str = "") -> Mechanism:
        """The chain as a :class:`Mechanism` (links "0".."n-1", joints "J0", "J1", ...)."""
        return Mechanism.build(
            [(f"J{k}", [str(x) for x in links]) for k, links in enumerate(self.joints)], name=name
        )

    def to_dict(self) -> dict[str, Any]:
        return {
            "canonical": self.canonical,
            "n": self.n,
            "F": self.F,
            "K": self.K,
            "V": self.V,
            "LA": list(self.LA),
            "MJA": list(self.MJA),
            "planar": self.planar,
            "fractionated": self.fractionated,
            "joints": [list(j) for j in self.joints],
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Chain:
        return cls(
            canonical=d["canonical"],
            n=d["n"],
            joints=tuple(tuple(j) for j in d["joints"]),
            LA=tuple(d["LA"]),
            MJA=tuple(d["MJA"]),
            V=d["V"],
            K=d["K"],
            F=d["F"],
            planar=d["planar"],
            fractionated=d["fractionated"],
        )


@dataclass
class Atlas:
    """The result of :func:`atlas`: sorted chains and how they were asked for."""

    F: int
    n: int
    mj: bool
    fractionated: bool
    chains: list[Chain] = field(default_factory=list)

    @property
    def count(self) -> int:
        return len(self.chains)


def _assortments(n: int, joints: Sequence[Sequence[int]]) -> tuple[tuple[int, ...], ...]:
    deg = [0] * n
    for js in joints:
        for x in js:
            deg[x] += 1
    la = [0] * (max(deg) - 1)
    for d in deg:
        la[d - 2] += 1
    mults = [len(js) - 1 for js in joints if len(js) > 2]
    mja = [0] * (max(mults, default=1) - 1)
    for j in mults:
        mja[j - 2] += 1
    return tuple(la), tuple(mja)


# -- expansion of a contracted graph ------------------------------------------------


def compositions(total: int, minima: list[int]) -> np.ndarray:
    """All integer vectors b >= minima with Σ b = total, one per row (every
    distribution, before any test: the reference the fast generation is checked by)."""
    e = len(minima)
    free = total - sum(minima)
    if free < 0:
        return np.zeros((0, e), dtype=np.int64)
    cuts = np.array(list(itertools.combinations(range(free + e - 1), e - 1)), dtype=np.int64)
    cuts = cuts.reshape(-1, e - 1)
    bounds = np.hstack([np.full((len(cuts), 1), -1), cuts, np.full((len(cuts), 1), free + e - 1)])
    return np.diff(bounds, axis=1) - 1 + np.asarray(minima, dtype=np.int64)


def expand(cg: ContractedGraph, b: Sequence[int]) -> tuple[int, list[list[int]]]:
    """The chain of a contracted graph with ``b[e]`` binary links on edge e: (n, joints)."""
    link_of: dict[int, int] = {}
    for v, c in enumerate(cg.colours):
        if c == "L":
            link_of[v] = len(link_of)
    n = len(link_of)
    multiple: dict[int, list[int]] = {v: [] for v, c in enumerate(cg.colours) if c == "J"}
    simple: list[list[int]] = []
    for (u, v), count in zip(cg.edges, b, strict=True):
        path: list[tuple[str, int]] = [("J", u) if u in multiple else ("L", link_of[u])]
        for _ in range(count):
            path.append(("L", n))
            n += 1
        path.append(("J", v) if v in multiple else ("L", link_of[v]))
        for (ka, a), (kc, z) in itertools.pairwise(path):
            if ka == "L" and kc == "L":
                simple.append([a, z])
            elif ka == "J":
                multiple[a].append(z)
            else:
                multiple[z].append(a)
    return n, simple + [multiple[v] for v in sorted(multiple)]


_BLAS: list[Any] = []  # threadpoolctl's controller, made once (it scans the libraries)


def _one_blas_thread() -> Any:
    """A context limiting BLAS to one thread: the tests of distributions are many small
    matrix products, for which waking BLAS threads costs more than it saves."""
    if not _BLAS:
        from threadpoolctl import ThreadpoolController

        _BLAS.append(ThreadpoolController())
    return _BLAS[0].limit(limits=1, user_api="blas")


_LIBC: list[Any] = []  # glibc, once (None elsewhere)


def _return_free_memory() -> None:
    """Give the memory freed by the previous task back to the system: glibc keeps it
    otherwise, and a worker that ran a large task would hold it to the end (the
    largest tasks run first)."""
    if not _LIBC:
        import ctypes

        try:
            _LIBC.append(ctypes.CDLL("libc.so.6").malloc_trim)
        except (OSError, AttributeError):
            _LIBC.append(None)
    if _LIBC[0] is not None:
        _LIBC[0](0)


@dataclass(frozen=True)
class TaskChains:
    """The chains of one task, compact for sending from a worker to the parent: what
    the task fixes once, then per chain its code (sorted; one string, a line each),
    joints, and planar/fractionated flags (one byte each: 2 planar + fractionated).

    Pickling a list of :class:`Chain` costs about as much as labelling the chains;
    this form pickles in a few milliseconds, and the parent makes the chains.
    """

    n: int
    LA: tuple[int, ...]
    MJA: tuple[int, ...]
    V: int
    K: int
    F: int
    codes: str
    joints: list[Joints]
    flags: bytes

    def chains(self) -> list[Chain]:
        """The chains, sorted by code."""
        if not self.joints:
            return []
        n, la, mja, V, K, F = self.n, self.LA, self.MJA, self.V, self.K, self.F
        return [
            Chain(code, n, joints, la, mja, V, K, F, flag > 1, flag & 1 == 1)
            for code, joints, flag in zip(
                self.codes.split("\n"), self.joints, self.flags, strict=True
            )
        ]


def _task_chains(task: tuple[tuple[Vertex, ...], int, int, bool]) -> list[Chain]:
    """Every admissible chain on the contracted graphs of one branch-vertex multiset,
    sorted by code (the task fixes V, [MJA] and [LA])."""
    return _task_compact(task).chains()


def _task_compact(task: tuple[tuple[Vertex, ...], int, int, bool]) -> TaskChains:
    """:func:`_task_chains` as :class:`TaskChains` (what a worker sends back)."""
    from mjstruct.synthesis.distributions import distributions_of
    from mjstruct.synthesis.expansion import expand_rows, labelled_lists
    from mjstruct.synthesis.parallel import collection_paused

    sequence, n, F, fractionated = task
    _return_free_memory()
    binaries = n - sum(1 for c, _ in sequence if c == "L")
    graphs = contracted_graphs(sequence, fractionated)
    # the steps that make many objects and no reference cycles run with the cyclic
    # collector paused; the planarity test (networkx: cycles) runs between them
    with _one_blas_thread(), collection_paused():
        found = [(cg, rows) for cg, rows in distributions_of(graphs, binaries) if len(rows)]
    kinds = [2 * cg.is_planar() + cg.is_fractionated() for cg, _ in found]
    codes: list[str] = []
    joints: list[Joints] = []
    flags = bytearray()
    shared: dict[tuple[int, int], dict[int, tuple[int, ...]]] = {}  # a tuple per joint
    la: tuple[int, ...] = ()
    mja: tuple[int, ...] = ()
    V = K = 0
    with collection_paused():
        for (cg, rows), kind in zip(found, kinds, strict=True):
            chains = expand_rows(cg, rows, binaries)
            first = chains.joints(0)
            la, mja = _assortments(chains.n, first)  # the task fixes them
            V = sum((k + 1) * nu for k, nu in enumerate(mja))
            K = sum(len(j) - 1 for j in first) - chains.n + 1
            more_codes, more_joints = labelled_lists(chains, shared)
            codes += more_codes
            joints += more_joints
            flags += bytes([kind]) * len(more_codes)
        order = sorted(range(len(codes)), key=codes.__getitem__)  # by code (codes differ)
        codes = [codes[k] for k in order]
        joints = [joints[k] for k in order]
        flags = bytearray(flags[k] for k in order)
    del found, shared
    _return_free_memory()  # before the result is pickled and the next task starts
    return TaskChains(
        n,
        la,
        mja,
        V,
        K,
        F,
        "\n".join(codes),
        joints,
        bytes(flags),
    )


def _cycle(n: int, F: int) -> Chain:
    joints = [[i, (i + 1) % n] for i in range(n)]
    code, canon = canonical_chain(n, joints)
    return Chain(code, n, canon, (n,), (), 0, 1, F, True, False)


def atlas_tasks(
    F: int, n: int, mj: bool = False, fractionated: bool = False
) -> list[tuple[tuple[Vertex, ...], int, int, bool]]:
    """The independent tasks of an atlas (one per branch-vertex multiset).

    A fractionated chain has F = F_A + F_B (a cut link) or F_A + F_B + 1 (a cut joint)
    with parts of F >= 1 each: none has F = 1, so its tasks skip the contracted graphs
    with cut vertices even when ``fractionated`` is asked.
    """
    K2 = n - 1 - F
    if K2 % 2 or K2 < 4:
        return []
    K = K2 // 2
    return [(seq, n, F, fractionated and F >= 2) for seq in degree_sequences(K, mj)]


def atlas(
    F: int,
    n: int,
    mj: bool = False,
    fractionated: bool = False,
    workers: int = 1,
    progress: Callable[[int, int], None] | None = None,
    scheduler: str | None = None,
    limit: int | None = CHAIN_LIMIT,
) -> Atlas:
    """All non-isomorphic admissible chains with ``F`` DOF and ``n`` links.

    Parameters
    ----------
    F, n : int
        Degrees of freedom (planar, one-freedom pairs) and number of links.
    mj : bool
        Also chains with multiple joints (simple-joint chains are always included).
    fractionated : bool
        Also chains whose link–joint graph has a cut vertex.
    workers : int
        Processes to use (the result does not depend on it).
    progress : callable, optional
        Called as ``progress(done, total)`` after each task.
    scheduler : str, optional
        Address of a Dask scheduler to run the tasks on (optional extra).
    limit : int or None
        Refuse (``MechanismError``) when about more chains than this are expected
        (:func:`mjstruct.synthesis.job_size.chain_count_estimate`); None: no limit.
    """
    expect_int(F, "F", 0)
    expect_int(n, "n")
    expect_int(workers, "workers")
    if n < 1:
        raise MechanismError(f"n: need at least one link, got {n}")
    if workers < 1:
        raise MechanismError(f"workers: need at least 1, got {workers}")
    kind = f"chains for F = {F}, n = {n}" + (" with MJs" if mj else "")
    estimate = chain_count_estimate(F, n, mj, fractionated)
    check_size(estimate, kind, limit, "limit", loops=(n - 1 - F) // 2)
    result = Atlas(F, n, mj, fractionated)
    if n - 1 - F == 2 and n >= 4:  # K = 1: the n-gon (and no task)
        result.chains.append(_cycle(n, F))
    # the largest tasks (most branch vertices) first, so that no worker is left with
    # one at the end; the chains are sorted afterwards, so the order does not matter
    tasks = atlas_tasks(F, n, mj, fractionated)[::-1]
    from mjstruct.synthesis.parallel import collection_paused, run_tasks

    # a task's chains share (V, [MJA], [LA]), which no other task has, and come
    # sorted by code: ordering the tasks is ordering the chains by sort_key.  Each
    # task's chains are made as it comes in, while the workers run the others.
    done = []
    with collection_paused():  # many objects, no cycles
        for compact in run_tasks(
            _task_compact,
            tasks,
            workers=workers,
            progress=progress,
            scheduler=scheduler,
            as_done=True,
        ):
            if compact.joints:
                done.append(((compact.V, compact.MJA, compact.LA), compact.chains()))
    done.sort(key=lambda made: made[0])
    for _, chains in done:
        result.chains.extend(chains)
    return result
