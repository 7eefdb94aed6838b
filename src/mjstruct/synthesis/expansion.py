"""From distributions of binary links to labelled chains, many at a time.

Owns the last step of the atlas: a contracted graph and the rows of binary-link
counts on its edges (:mod:`mjstruct.synthesis.distributions`) become chains with their
canonical codes and their joints in canonical order.  Everything but nauty's search
works on whole arrays of rows:

- the expansion: every edge becomes a path of binary links; for each row the paths'
  link numbers are laid end to end in one array, and consecutive pairs are the joints
  (both ends links: a simple joint; one end a multiple joint: a link on it);
- one nauty call per chain (the canonical labelling,
  :func:`mjstruct.synthesis.nauty_calls.canon_label`);
- the canonical joints (as integer keys, sorted, each key decoded once) and nauty's
  certificate (the canonical graph's adjacency rows: 64-bit words whose bit ``63 -
  j`` is neighbour j, stored little-endian) from the labellings, so that the code is
  the one :func:`mjstruct.structure.isomorphism.canonical_code` gives.

Examples
--------
>>> from mjstruct.synthesis.contracted import contracted_graphs
>>> from mjstruct.synthesis.distributions import chain_distributions
>>> theta = contracted_graphs((("L", 3), ("L", 3)), fractionated=False)[0]
>>> cg, rows = chain_distributions(theta, 4)
>>> chains = expand_rows(cg, rows, 4)
>>> chains.n, chains.joints(0)
(6, [[0, 1], [0, 2], [2, 3], [3, 1], [0, 4], [4, 5], [5, 1]])
>>> from mjstruct.synthesis.canonical_chains import chain_code
>>> codes = [code for code, _ in labelled_chains(chains)]
>>> codes == [chain_code(6, chains.joints(r))[0] for r in range(2)]
True
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mjstruct.structure.isomorphism import QUOTIENT_VERTICES, code_of
from mjstruct.synthesis.canonical_chains import canonical_chain
from mjstruct.synthesis.contracted import ContractedGraph
from mjstruct.synthesis.nauty_calls import LightGraph, canon_labels

Joints = tuple[tuple[int, ...], ...]

BATCH = 4096
"""Chains labelled per array step (bounds the memory of the adjacency matrices)."""


@dataclass(frozen=True)
class ExpandedChains:
    """Chains of ``n`` links with the same joint sizes: ``simple[r]`` the simple
    joints of chain r (pairs of links), ``members[r]`` the links on its multiple
    joints, joint after joint (``sizes``: links per multiple joint)."""

    n: int
    simple: np.ndarray  # (chains, simple joints, 2)
    members: np.ndarray  # (chains, Σ sizes)
    sizes: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.simple)

    def joints(self, r: int) -> list[list[int]]:
        """Chain r as joints (simple ones first), as :func:`expand` gives it."""
        out: list[list[int]] = self.simple[r].tolist()
        links = self.members[r].tolist()
        start = 0
        for size in self.sizes:
            out.append(links[start : start + size])
            start += size
        return out


def expand_rows(cg: ContractedGraph, rows: np.ndarray, binaries: int) -> ExpandedChains:
    """The chains of ``cg`` with ``rows[r, e]`` binary links on edge e, links numbered
    as :func:`mjstruct.synthesis.atlas.expand` numbers them (branch links first, then
    the binary links edge by edge)."""
    ne = len(cg.edges)
    link_of: dict[int, int] = {}
    joint_of: dict[int, int] = {}
    for v, c in enumerate(cg.colours):
        if c == "L":
            link_of[v] = len(link_of)
        else:
            joint_of[v] = len(joint_of)
    nb = len(link_of)

    def node(v: int) -> int:  # links >= 0, multiple joint q as -1 - q
        return link_of[v] if v in link_of else -1 - joint_of[v]

    sizes = [0] * len(joint_of)
    for u, v in cg.edges:
        for x in {u, v} if u != v else [u, u]:
            if x in joint_of:
                sizes[joint_of[x]] += 1
    R = len(rows)
    if R == 0:
        return ExpandedChains(
            nb + binaries, np.zeros((0, 0, 2), dtype=np.int64), np.zeros((0, 0), np.int64), ()
        )
    start = np.array([node(u) for u, _ in cg.edges], dtype=np.int64)
    end = np.array([node(v) for _, v in cg.edges], dtype=np.int64)
    b = rows.astype(np.int64)
    first = nb + np.cumsum(b, axis=1) - b  # first binary link of each edge
    length = b + 2  # path nodes: start, the binaries, end
    width = binaries + 2 * ne
    seg = np.repeat(np.tile(np.arange(ne), R), length.ravel())
    row = np.repeat(np.arange(R), width)
    where = row * ne + seg
    local = (
        np.arange(R * width) - row * width - (np.cumsum(length, axis=1) - length).ravel()[where]
    )
    count = b.ravel()[where]
    value = first.ravel()[where] + local - 1
    value = np.where(local == 0, start[seg], value)
    value = np.where(local == count + 1, end[seg], value)
    pair = local[:-1] < count[:-1] + 1  # consecutive nodes of one path
    pairs = np.stack([value[:-1][pair], value[1:][pair]], axis=1).reshape(R, binaries + ne, 2)
    simple = (pairs >= 0).all(axis=2)
    n_simple = binaries + ne - sum(sizes)
    sj = pairs[simple].reshape(R, n_simple, 2)
    on = pairs[~simple].reshape(R, sum(sizes), 2)
    joint = np.where(on[:, :, 0] < 0, on[:, :, 0], on[:, :, 1])  # -1 - q
    member = np.where(on[:, :, 0] < 0, on[:, :, 1], on[:, :, 0])
    order = np.argsort(-joint, axis=1, kind="stable")  # q = 0, 1, ...
    member = np.take_along_axis(member, order, axis=1)
    return ExpandedChains(nb + binaries, sj, member, tuple(sizes))


def labelled_chains(
    chains: ExpandedChains, shared: dict[tuple[int, int], dict[int, tuple[int, ...]]] | None = None
) -> list[tuple[str, Joints]]:
    """Canonical code and canonical joints (sorted, links in nauty's canonical order)
    of every chain.  ``shared`` keeps one tuple per distinct joint across calls."""
    codes, joints = labelled_lists(chains, shared)
    return list(zip(codes, joints, strict=True))


def labelled_lists(
    chains: ExpandedChains, shared: dict[tuple[int, int], dict[int, tuple[int, ...]]] | None = None
) -> tuple[list[str], list[Joints]]:
    """:func:`labelled_chains` as two lists, the codes and the joints (no pair per chain)."""
    n, p = chains.n, chains.simple.shape[1] + len(chains.sizes)
    codes: list[str] = []
    joints: list[Joints] = []
    if not len(chains):
        return codes, joints
    if n + p >= QUOTIENT_VERTICES:  # large chains: as canonical_code does them
        for r in range(len(chains)):
            code, canon = canonical_chain(n, chains.joints(r))
            codes.append(code)
            joints.append(canon)
        return codes, joints
    if shared is None:
        shared = {}
    table = shared.setdefault((n, max([2, *chains.sizes])), {})
    for lo in range(0, len(chains), BATCH):
        part = slice(lo, lo + BATCH)
        more_codes, more_joints = _labelled(
            n, chains.simple[part], chains.members[part], chains.sizes, table
        )
        codes += more_codes
        joints += more_joints
    return codes, joints


def _labelled(
    n: int,
    simple: np.ndarray,
    members: np.ndarray,
    sizes: tuple[int, ...],
    shared: dict[int, tuple[int, ...]],
) -> tuple[list[str], list[Joints]]:
    R, n_simple = simple.shape[0], simple.shape[1]
    p = n_simple + len(sizes)
    nv = n + p
    keys = range(n, nv)
    # a simple joint's adjacency: one shared list per pair of links (nauty only reads
    # them), looked up by a + n b: no nested lists made per chain
    pair_lists = [[a, b] for b in range(n) for a in range(n)]
    pair_index = (simple[:, :, 0] + n * simple[:, :, 1]).tolist()
    if not sizes:
        graphs = (
            dict(zip(keys, map(pair_lists.__getitem__, row), strict=True)) for row in pair_index
        )
    else:
        if len(set(sizes)) == 1:  # multiple joints of one size: nested lists in one call
            on_joints = members.reshape(R, len(sizes), sizes[0]).tolist()
        else:
            bounds = np.cumsum([0, *sizes]).tolist()
            on_joints = [
                [links[bounds[q] : bounds[q + 1]] for q in range(len(sizes))]
                for links in members.tolist()
            ]
        graphs = (
            dict(zip(keys, [*map(pair_lists.__getitem__, row), *multiple], strict=True))
            for row, multiple in zip(pair_index, on_joints, strict=True)
        )
    labs = canon_labels(LightGraph(nv, {}, [range(n), range(n, nv)]), graphs)
    where = np.argsort(np.array(labs, dtype=np.int64), axis=1)  # vertex -> position
    rows = np.arange(R)[:, None]
    # canonical positions of the links on each joint, sorted within the joint
    two = np.sort(where[rows[:, :, None], simple], axis=2)
    on = where[rows, members]
    bounds = np.cumsum([0, *sizes]).tolist()
    # nauty's certificate: the canonical adjacency, one 64-bit word per vertex
    owner = np.concatenate(
        [np.repeat(np.arange(n_simple), 2), np.repeat(n_simple + np.arange(len(sizes)), sizes)]
    )
    link_pos = np.concatenate([two.reshape(R, -1), on], axis=1)
    joint_pos = where[:, n + owner]
    adjacency = np.zeros((R, nv, 64), dtype=bool)
    r = np.repeat(np.arange(R), len(owner))
    adjacency[r, joint_pos.ravel(), link_pos.ravel()] = True
    adjacency[r, link_pos.ravel(), joint_pos.ravel()] = True
    words = np.packbits(adjacency, axis=2, bitorder="big")[:, :, ::-1]  # little-endian
    # each joint as one integer: its sorted links (+1) in base n + 1, padded with 0
    # after the end, so that integer order is the order of the tuples
    width = max([2, *sizes])
    radix = n + 1
    scale = radix ** np.arange(width - 1, -1, -1, dtype=np.int64)
    key_parts = [(two + 1) @ scale[:2]]
    for q in range(len(sizes)):
        links = np.sort(on[:, bounds[q] : bounds[q + 1]], axis=1) + 1
        key_parts.append((links @ scale[: sizes[q]])[:, None])
    joint_keys = np.sort(np.concatenate(key_parts, axis=1), axis=1)
    powers = scale.tolist()
    for key in np.unique(joint_keys).tolist():
        if key not in shared:
            digits = [key // power % radix for power in powers]
            shared[key] = tuple(d - 1 for d in digits if d)
    sizes_text = f"{n}.{p}"
    lookup = shared.__getitem__
    codes = [code_of("c", n, p, sizes_text, cert) for cert in _rows_as_bytes(words)]
    return codes, [tuple(map(lookup, row)) for row in joint_keys.tolist()]


def _rows_as_bytes(words: np.ndarray) -> list[bytes]:
    """Each row (first axis) of ``words`` as bytes: one copy, then slices."""
    blob, step = words.tobytes(), words[0].nbytes if len(words) else 0
    return [blob[start : start + step] for start in range(0, len(blob), step)]
