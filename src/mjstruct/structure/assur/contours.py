"""Artobolevsky's class of an Assur group from its contours and its joints per link.

This module owns :func:`group_class`: the largest number of links in an elementary
closed contour of internal joints, or the largest number of internal joints on one
link (the base link of a triad: 3), at least 2 (a dyad).  A multiple joint is one
vertex of the contour graph, so a contour never passes twice through it.

References
----------
.. [1] L. V. Assur, "Investigation of planar bar mechanisms with lower pairs from the
   point of view of their structure and classification" (in Russian), Bulletin of
   the Petrograd Polytechnic Institute, 1913–1914. [Assur 1914] in docs/references.md.
.. [2] I. I. Artobolevsky, Theory of Mechanisms and Machines (in Russian), Moscow:
   Nauka, 1988. [Artobolevsky 1988] in docs/references.md.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Sequence


def group_class(bodies: Iterable[Hashable], internal: Sequence[Sequence[Hashable]]) -> int:
    """Artobolevsky class of a group from its bodies and internal joints (body lists).

    >>> group_class(["a", "b"], [["a", "b"]])                       # dyad
    2
    >>> group_class("abcd", [["a", "d"], ["b", "d"], ["c", "d"]])   # triad
    3
    >>> group_class("abcd", [["a", "b"], ["b", "c"], ["c", "d"], ["d", "a"]])
    4
    """
    per_body = dict.fromkeys(bodies, 0)
    for touched in internal:
        for b in touched:
            per_body[b] += 1
    base = max(per_body.values(), default=0)
    edges = sum(len(t) for t in internal)
    if edges - len(internal) - len(per_body) + 1 <= 0:  # bipartite graph is a tree
        return max(2, base)
    return max(2, base, longest_contour(internal))


def longest_contour(internal: Sequence[Sequence[Hashable]]) -> int:
    """Largest number of links on the shortest closed contour through any incidence.

    The contour graph is bipartite (links, internal joints), so an MJ is one vertex and
    a contour never passes twice through it; a contour of k links has 2k edges.

    >>> longest_contour([["a", "b"], ["b", "c"], ["c", "a"]])
    3
    """
    body_ix: dict[Hashable, int] = {}
    for touched in internal:
        for b in touched:
            body_ix.setdefault(b, len(body_ix))
    first_joint = len(body_ix)  # vertices: bodies, then one per internal joint
    adj: list[list[int]] = [[] for _ in range(first_joint + len(internal))]
    for k, touched in enumerate(internal):
        for b in touched:
            adj[first_joint + k].append(body_ix[b])
            adj[body_ix[b]].append(first_joint + k)
    longest = 0
    for k, touched in enumerate(internal):
        goal = first_joint + k
        for b in touched:
            # shortest path body -> joint that avoids the edge itself, by BFS
            start = body_ix[b]
            dist = [-1] * len(adj)
            dist[start] = 0
            frontier = [start]
            found = -1
            while frontier and found < 0:
                nxt = []
                for x in frontier:
                    for y in adj[x]:
                        if dist[y] >= 0 or (x == start and y == goal):
                            continue
                        dist[y] = dist[x] + 1
                        if y == goal:
                            found = dist[y]
                            break
                        nxt.append(y)
                    if found >= 0:
                        break
                frontier = nxt
            if found >= 0:
                longest = max(longest, (found + 1) // 2)
    return longest
