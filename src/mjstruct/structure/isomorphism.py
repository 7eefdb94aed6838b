"""Exact isomorphism of chains and mechanisms by canonical labelling (pynauty).

The bipartite link–joint graph is coloured (links vs joints; at the ``"kinds"`` level
also R vs P joints; at the ``"mechanism"`` level also the frame and the driven joints)
and put in nauty's canonical form.  The canonical code is a short stable string: the
colour-class sizes and a SHA-256 digest of nauty's certificate, so two files get the
same code exactly when their coloured graphs are isomorphic (up to a 128-bit digest
collision).

Parallel joints are a multiplicity, not a search problem.  Joints that join the same
links (or links in the same joints), in one colour class, are *twins*: any permutation
of them is an automorphism, and nauty's search over thousands of them takes minutes
(3000 joints between two links: over 120 s).  In a graph of :data:`QUOTIENT_VERTICES`
vertices or more where some class of twins has :data:`TWINS_QUOTIENT` or more
members, each class is replaced by one vertex coloured by its size; two graphs are
isomorphic exactly when these quotients are (twins map to twins), so the code stays
exact.  Parallel *chains* are the larger kind of twins: k binary links each joining
links 0 and 1 through two joints (any path of vertices of degree two between the same
two ends, with the same colours along it); they too are kept once with their number
as a colour (:func:`chain_quotient`; 1500 such paths took nauty about a minute).  The
rules depend only on the graph, so isomorphic chains always take the same path;
smaller chains (every catalog and atlas chain) keep their codes.

nauty runs in C and holds the interpreter: a graph of :data:`WORKER_VERTICES`
vertices or more is put in canonical form in a worker process, so that Ctrl-C and
SIGTERM stop the command at once (the worker is killed); below, nauty takes at most
a few tens of milliseconds on the graphs it finds hardest (a star of pendant links
of that size: 0.03 s).

References
----------
.. [1] B. D. McKay, A. Piperno, "Practical graph isomorphism, II", Journal of
   Symbolic Computation, vol. 60, pp. 94–112, 2014. [McKay & Piperno 2014] in
   docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> a = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 3]), ("d", [3, 0])])
>>> b = Mechanism.build(
...     [("x", ["p", "q"]), ("y", ["r", "q"]), ("z", ["s", "p"]), ("w", ["r", "s"])]
... )
>>> canonical_code(a) == canonical_code(b)
True
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from typing import Any, Literal

import pynauty

try:  # CPython's own SHA-256: hashlib's OpenSSL library costs a tenth of a CLI start-up
    from _sha256 import sha256
except ImportError:  # another interpreter or version: the same digest from hashlib
    from hashlib import sha256

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Mechanism, expect_mechanism

Level = Literal["chain", "kinds", "mechanism"]
LEVELS: tuple[str, ...] = ("chain", "kinds", "mechanism")


def nauty_graph(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]] | None = None
) -> pynauty.Graph:
    """The nauty graph of an incidence structure: every structure of the package.

    Vertices ``0..n-1`` are the links (or the vertices of a multigraph), vertex
    ``n + k`` is joint ``k`` (or edge ``k``), adjacent to the vertices it joins; a
    joint of one vertex is a loop of a multigraph.  ``colours`` partition the vertices
    (default: links, joints); empty classes are dropped.

    >>> g = nauty_graph(3, [[0, 1], [1, 2], [2, 0]])
    >>> g.number_of_vertices, len(pynauty.autgrp(g)[0])  # a triangle: 3 generators
    (6, 2)
    """
    p = len(joints)
    if colours is None:
        colours = [range(n), range(n, n + p)]
    return pynauty.Graph(
        n + p,
        directed=False,
        adjacency_dict={n + k: list(js) for k, js in enumerate(joints)},
        vertex_coloring=[set(c) for c in colours if c],
    )


def code_of(level_prefix: str, n: int, p: int, sizes: str, certificate: bytes) -> str:
    """The canonical code string: prefix, counts and a 128-bit digest of the certificate.

    ``sizes`` are the colour-class sizes (they make the certificate comparable).
    """
    digest = sha256(sizes.encode() + b"|" + certificate).hexdigest()[:32]
    return f"{level_prefix}{n}.{p}-{digest}"


def colour_classes(m: Mechanism, level: str) -> list[list[int]]:
    """Vertex colour classes of ``m`` at ``level`` (links first, then joints, file order).

    >>> from mjstruct.mechanism import Mechanism
    >>> m = Mechanism.build([("a", [0, 1]), ("b", [1, 2]), ("c", [2, 0], "P")], frame=0)
    >>> colour_classes(m, "chain"), colour_classes(m, "mechanism")
    ([[0, 1, 2], [3, 4, 5]], [[0], [1, 2], [], [], [3, 4], [5]])
    """
    n = len(m.links)
    link_ix = {link: i for i, link in enumerate(m.links)}
    if level == "chain":
        return [list(range(n)), list(range(n, n + len(m.joints)))]
    if level not in ("kinds", "mechanism"):
        raise MechanismError(f"level: must be one of {', '.join(LEVELS)}, got {level!r}")
    mech = level == "mechanism"
    frame = [link_ix[m.frame]] if mech and m.frame is not None else []
    others = [i for i in range(n) if i not in frame]
    drivers = set(m.drivers) if mech else set()
    classes = [frame, others]
    for driven in (True, False):
        for kind in ("R", "P"):
            classes.append(
                [
                    n + k
                    for k, j in enumerate(m.joints)
                    if j.kind == kind and (j.id in drivers) == driven
                ]
            )
    return classes


def link_joint_lists(m: Mechanism) -> list[list[int]]:
    """Each joint of ``m`` as the indices of its links (the input of :func:`nauty_graph`)."""
    link_ix = {link: i for i, link in enumerate(m.links)}
    return [[link_ix[x] for x in j.links] for j in m.joints]


#: a class of this many twins (parallel joints, or links in the same joints) or more
#: puts the graph in nauty's form as its quotient by twins ...
TWINS_QUOTIENT = 3
#: ... in a graph of this many vertices or more (below, nauty takes microseconds and
#: the codes of small chains, the atlases' among them, stay as they were)
QUOTIENT_VERTICES = 64
#: graphs with this many vertices (links + joints) or more go to nauty in a worker
#: process (10-20 ms to start; below, nauty takes at most a few tens of milliseconds
#: on the hardest graphs measured, but may take minutes on a large symmetric graph,
#: during which the interpreter receives no signal: benchmarks/bench_nauty_worker.py)
WORKER_VERTICES = 400


def twin_quotient(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]]
) -> tuple[int, list[list[int]], list[list[int]], str] | None:
    """The graph with each class of twins as one vertex coloured by the class's size.

    Twins: links with the same set of joints, or joints with the same set of links,
    in the same colour class.  Returns ``(n, joints, colours, sizes)`` of the quotient
    (``sizes`` names its colour classes: original class, multiplicity and count), or
    None when no class has :data:`TWINS_QUOTIENT` members.

    Five joints between links 0 and 1 (the two links are twins too):

    >>> twin_quotient(2, [[0, 1]] * 5, [[0, 1], range(2, 7)])
    (1, [[0]], [[0], [1]], 'q0x2:1.1x5:1')
    """
    p = len(joints)
    colour_of = [0] * (n + p)
    for c, members in enumerate(colours):
        for v in members:
            colour_of[v] = c
    at: list[list[int]] = [[] for _ in range(n)]
    for k, js in enumerate(joints):
        for x in js:
            at[x].append(n + k)
    keys = [(colour_of[x], frozenset(at[x])) for x in range(n)]
    keys += [(colour_of[n + k], frozenset(js)) for k, js in enumerate(joints)]
    first: dict[tuple[int, frozenset[int]], int] = {}
    count: dict[int, int] = {}
    for v, key in enumerate(keys):
        rep = first.setdefault(key, v)
        count[rep] = count.get(rep, 0) + 1
    if max(count.values()) < TWINS_QUOTIENT:
        return None
    reps = sorted(count)  # links before joints, each in file order
    link_reps = [v for v in reps if v < n]
    new = {v: i for i, v in enumerate(link_reps)}
    q_joints = [sorted({new[first[keys[x]]] for x in joints[v - n]}) for v in reps if v >= n]
    position = {v: i for i, v in enumerate(reps)}
    classes: dict[tuple[int, int], list[int]] = {}
    for v in reps:
        classes.setdefault((colour_of[v], count[v]), []).append(position[v])
    order = sorted(classes)
    sizes = "q" + ".".join(f"{c}x{mult}:{len(classes[c, mult])}" for c, mult in order)
    return len(link_reps), q_joints, [classes[key] for key in order], sizes


def chain_quotient(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]]
) -> tuple[int, list[list[int]], list[list[int]], str] | None:
    """The graph with each class of parallel chains kept once, coloured by its size.

    A *chain* is a path of vertices of degree two between two vertices of another
    degree, its *ends* (the same vertex for a cycle through it).  Chains with the same
    ends and the same colours along them (read from the lower end; a cycle either way)
    form a class; every class of :data:`TWINS_QUOTIENT` or more is replaced by one of
    its chains whose vertices are coloured by the class's size.  Returns ``(n, joints,
    colours, sizes)`` as :func:`twin_quotient` does (``sizes`` names the colour
    classes: original class, multiplicity and count), or None when no class is that
    large.

    Exact: two graphs are isomorphic (colours kept) exactly when their quotients are
    (the classes of colours taken in the order of ``sizes``).  Chains are disjoint by
    construction (their inner vertices have degree two, their ends do not), so the
    members of a class are interchangeable, and an inner vertex is adjacent only to
    its chain's neighbours or ends.  An isomorphism of the graphs maps chains to
    chains and classes to classes of the same size; mapping each kept chain to the
    image's kept chain (inner vertices in order) gives an isomorphism of the
    quotients.  Conversely an isomorphism of the quotients maps the vertices coloured
    with a size m >= 3 onto such vertices, hence each kept chain (a connected run of
    them) onto a kept chain of the same size, colours along it and ends; the m
    members of each class are then mapped member by member, the rest as the
    quotients' map: an isomorphism of the graphs.

    Five binary links each joining links 0 and 1 through two joints:

    >>> joints = [[0, 2 + k] for k in range(5)] + [[2 + k, 1] for k in range(5)]
    >>> chain_quotient(7, joints, [range(7), range(7, 17)])
    (3, [[0, 2], [2, 1]], [[0, 1], [2], [3, 4]], 'p0x1:2.0x5:1.1x5:2')
    """
    p = len(joints)
    colour_of = [0] * (n + p)
    for c, members in enumerate(colours):
        for v in members:
            colour_of[v] = c
    around: list[set[int]] = [set() for _ in range(n + p)]
    for k, js in enumerate(joints):
        for x in js:
            around[n + k].add(x)
            around[x].add(n + k)
    inner = [len(a) == 2 for a in around]
    seen = [False] * (n + p)
    classes: dict[tuple[int, int, tuple[int, ...]], list[list[int]]] = {}
    for u in range(n + p):
        if inner[u]:
            continue
        for w in sorted(around[u]):
            if not inner[w] or seen[w]:
                continue
            path, prev, cur = [], u, w
            while inner[cur]:
                seen[cur] = True
                path.append(cur)
                a, b = around[cur]
                prev, cur = cur, (b if a == prev else a)
            seq = tuple(colour_of[x] for x in path)
            if cur < u or (cur == u and seq[::-1] < seq):
                path.reverse()
                seq = seq[::-1]
            classes.setdefault((min(u, cur), max(u, cur), seq), []).append(path)
    if not classes or max(len(c) for c in classes.values()) < TWINS_QUOTIENT:
        return None
    mult = [1] * (n + p)
    dropped = [False] * (n + p)
    for alike in classes.values():
        if len(alike) >= TWINS_QUOTIENT:
            for x in alike[0]:
                mult[x] = len(alike)
            for other in alike[1:]:
                for x in other:
                    dropped[x] = True
    kept = [v for v in range(n + p) if not dropped[v]]  # links first, each in order
    new = {v: i for i, v in enumerate(kept)}
    n_new = sum(v < n for v in kept)
    q_joints = [[new[x] for x in joints[v - n] if not dropped[x]] for v in kept if v >= n]
    by_key: dict[tuple[int, int], list[int]] = {}
    for v in kept:
        by_key.setdefault((colour_of[v], mult[v]), []).append(new[v])
    order = sorted(by_key)
    sizes = "p" + ".".join(f"{c}x{m}:{len(by_key[c, m])}" for c, m in order)
    return n_new, q_joints, [by_key[key] for key in order], sizes


def canonical_code(m: Mechanism, level: Level = "chain") -> str:
    """Stable string identifying ``m`` up to isomorphism at the given colour level.

    ``"chain"``: links and joints only (what structural synthesis and the catalogs
    use); ``"kinds"``: also R/P; ``"mechanism"``: also frame and drivers.  Thousands of
    parallel joints cost what one does (:func:`twin_quotient`).

    >>> parallel = Mechanism.build([(f"J{k}", [0, 1]) for k in range(3000)])
    >>> canonical_code(parallel)
    'c2.3000-8ac0051af4bbf08a64cd48896656400b'
    """
    expect_mechanism(m)
    classes = colour_classes(m, level)
    sizes, cert = certificate_of(len(m.links), link_joint_lists(m), classes)
    prefix = {"chain": "c", "kinds": "k", "mechanism": "m"}[level]
    return code_of(prefix, len(m.links), len(m.joints), sizes, cert)


def certificate_of(
    n: int, joints: Sequence[Sequence[int]], colours: Sequence[Collection[int]]
) -> tuple[str, bytes]:
    """The colour-class sizes and nauty's certificate behind a canonical code: of the
    twin and chain quotients where the rule applies (see the module text), in a
    worker process for a large graph.

    >>> sizes, cert = certificate_of(3, [[0, 1], [1, 2], [2, 0]], [range(3), range(3, 6)])
    >>> sizes, len(cert)
    ('3.3', 48)
    """
    sizes = ".".join(str(len(c)) for c in colours)
    if n + len(joints) >= QUOTIENT_VERTICES:
        quotient = twin_quotient(n, joints, colours)
        if quotient is not None:
            n, joints, colours, sizes = quotient
        chains = chain_quotient(n, joints, colours)
        if chains is not None:  # the classes' meaning: the twins' sizes, then its own
            n, joints, colours, more = chains
            sizes = f"{sizes}|{more}"
    cert = nauty_call("certificate", n, joints, colours)
    assert isinstance(cert, bytes)
    return sizes, cert


def nauty_call(
    what: Literal["certificate", "canon_label"],
    n: int,
    joints: Sequence[Sequence[int]],
    colours: Sequence[Collection[int]] | None = None,
) -> bytes | list[int]:
    """``pynauty.certificate`` or ``pynauty.canon_label`` of :func:`nauty_graph`, in a
    worker process for a graph of :data:`WORKER_VERTICES` vertices or more (so a
    signal stops it at once), else here.

    >>> nauty_call("canon_label", 3, [[0, 1], [1, 2]])
    [0, 2, 1, 3, 4]
    """
    args = (
        what,
        n,
        [list(j) for j in joints],
        None if colours is None else [list(c) for c in colours],
    )
    if n + len(joints) < WORKER_VERTICES or not _may_fork():
        return _nauty(*args)
    return _in_worker(args)


def _nauty(
    what: str, n: int, joints: list[list[int]], colours: list[list[int]] | None
) -> bytes | list[int]:
    g = nauty_graph(n, joints, colours)
    out: bytes | list[int] = getattr(pynauty, what)(g)
    return out


def _may_fork() -> bool:
    """A worker can be started: not inside a daemon worker (a pool's), on the main
    thread (where signals arrive)."""
    import multiprocessing
    import threading

    return (
        not multiprocessing.current_process().daemon
        and threading.current_thread() is threading.main_thread()
    )


def _worker(send: Any, args: tuple[Any, ...], parent: int) -> None:
    import signal

    # the parent decides: a signal to the group must not make the worker raise
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    die_with_parent(parent)
    send.send(_nauty(*args))
    send.close()


def die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent ends, whatever ends it (even
    SIGKILL, where the parent's cleanup cannot run); elsewhere nothing.

    Called first thing in a worker process (here and in the atlas's process pool).

    Parameters
    ----------
    parent : int
        The parent's process id, taken before the fork: a worker whose parent has
        already gone (its parent id differs) ends at once.
    """
    import ctypes
    import os
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return
    try:
        # the running program's symbols: the C library's prctl
        ctypes.CDLL(None).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # pragma: no cover - no prctl: the parent kills it
        return
    if os.getppid() != parent:  # the parent ended before the request: end now
        os._exit(1)


def _in_worker(args: tuple[Any, ...]) -> bytes | list[int]:
    """Run :func:`_nauty` in a child process; the parent waits where signals arrive
    and kills the child on any exception (Ctrl-C, SIGTERM), wherever it lands."""
    import multiprocessing
    import os

    ctx = multiprocessing.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_worker, args=(send, args, os.getpid()), daemon=True)
    try:
        child.start()
        send.close()
        # a blocking receive is interrupted by a signal, whose handler raises here
        out: bytes | list[int] = recv.recv()
        return out
    except EOFError:
        raise RuntimeError(f"nauty worker ended with status {child.exitcode}") from None
    finally:
        send.close()
        recv.close()
        if child.pid is not None:  # started (a signal may land inside start())
            child.kill()
            child.join()


def is_isomorphic(a: Mechanism, b: Mechanism, level: Level = "chain") -> bool:
    """Exact isomorphism test at the given colour level."""
    expect_mechanism(a, "a")
    expect_mechanism(b, "b")
    return canonical_code(a, level) == canonical_code(b, level)
