"""Shortest paths between known centres across the placed cluster, for triangle counts.

Owns :class:`ClusterPaths`: the length and the number of shortest paths from one
known joint centre to others, alternating known centres and placed links (the
triangles a dyad spends to find its base side, :meth:`PlanState.paths
<mjstruct.kinematics.steps.base.PlanState.paths>`).  A query is a breadth-first
search that stops after the layer of the first target.  A source queried again and
again across a large cluster (a multiple joint every dyad starts from, whose bases all
run through the frame) gets a *tree*: its distances and path counts to the whole
cluster, repaired as links are placed and centres become known, so that a query costs
a lookup instead of a search.  A tree is built only once searches from its source
have cost as much as the tree, and dropped when keeping it up to date costs more than
the searches it saves; either way the answers are the same.

Examples
--------
>>> links_of = {"A": ("1", "2"), "B": ("2", "3"), "C": ("3", "1")}
>>> revolute = {"1": ("A", "C"), "2": ("A", "B"), "3": ("B", "C")}
>>> cp = ClusterPaths(links_of, revolute, placed={"1", "2", "3"}, known={"A", "B", "C"})
>>> cp.distances("A", {"B"}, full=False)
{'B': (2, 1)}
"""

from __future__ import annotations

import heapq
from collections.abc import Mapping

#: trees kept at once (each placement updates every tree)
MAX_TREES = 4
#: search work from one source, in cluster sizes, that earns it a tree
GROW_AFTER = 2


class _Tree:
    """Distances and shortest-path counts from one source, joints and links apart."""

    __slots__ = ("dj", "dl", "idle", "sj", "sl")

    def __init__(self) -> None:
        self.dj: dict[str, int] = {}
        self.sj: dict[str, int] = {}
        self.dl: dict[str, int] = {}
        self.sl: dict[str, int] = {}
        self.idle = 0  # repair work since the last query


class ClusterPaths:
    """Breadth-first shortest paths over known centres and placed links.

    ``placed`` and ``known`` are the planner's own sets (read, never changed here);
    :meth:`link_placed` and :meth:`joint_known` must be called after each addition.
    ``visits`` counts the nodes the searches and repairs touched (the work a plan
    spends on triangle counts).
    """

    def __init__(
        self,
        links_of: Mapping[str, tuple[str, ...]],
        revolute: Mapping[str, tuple[str, ...]],
        placed: set[str],
        known: set[str],
    ) -> None:
        self.links_of, self.revolute = links_of, revolute
        self.placed, self.known = placed, known
        self.trees: dict[str, _Tree] = {}
        self.spent: dict[str, int] = {}  # search work per source without a tree
        self.visits = 0

    # -- queries --
    def distances(self, a: str, targets: set[str], full: bool) -> dict[str, tuple[int, int]]:
        """Edges and number of shortest paths from joint ``a`` to ``targets``.

        Only the targets at the smallest distance, unless ``full`` (then every
        reachable target).
        """
        if a not in self.known:
            return {}
        if a in targets:
            return {a: (0, 1)}
        tree = self.trees.get(a)
        if tree is None:
            found, work = self._search(a, targets, full)
            self.visits += work
            self.spent[a] = spent = self.spent.get(a, 0) + work
            # a tree costs about the cluster's size: worth it once searches cost more
            size = len(self.placed) + len(self.known)
            if spent >= GROW_AFTER * size and len(self.trees) < MAX_TREES:
                self.trees[a] = self._grow(a)
                del self.spent[a]
            return found
        tree.idle = 0
        dj, sj = tree.dj, tree.sj
        found = {t: (dj[t], sj[t]) for t in targets if t in dj}
        if not full and found:
            least = min(d for d, _ in found.values())
            found = {t: v for t, v in found.items() if v[0] == least}
        return found

    def _search(
        self, a: str, targets: set[str], full: bool
    ) -> tuple[dict[str, tuple[int, int]], int]:
        """Breadth first from ``a``; stops after the layer of the first target unless
        ``full``.  Returns the targets found and the nodes visited."""
        # joints and links kept apart (no tuple per node): the same breadth-first
        # counts, a smaller constant on multiple joints of many links
        placed, known = self.placed, self.known
        links_of, revolute = self.links_of, self.revolute
        dj: dict[str, int] = {a: 0}
        sj: dict[str, int] = {a: 1}
        dl: dict[str, int] = {}
        sl: dict[str, int] = {}
        frontier = [a]
        found: dict[str, tuple[int, int]] = {}
        d = 0
        while frontier:
            nxt: list[str] = []
            if d % 2 == 0:  # joints -> placed links
                for node in frontier:
                    w = sj[node]
                    for x in links_of[node]:
                        if x in placed:
                            if x not in dl:
                                dl[x] = d + 1
                                sl[x] = w
                                nxt.append(x)
                            elif dl[x] == d + 1:
                                sl[x] += w
            else:  # links -> known revolute centres
                for node in frontier:
                    w = sl[node]
                    for j in revolute[node]:
                        if j in known:
                            if j not in dj:
                                dj[j] = d + 1
                                sj[j] = w
                                nxt.append(j)
                            elif dj[j] == d + 1:
                                sj[j] += w
            d += 1
            if d % 2 == 0:
                for j in nxt:
                    if j in targets:
                        found[j] = (d, sj[j])
            if found and (not full or len(found) == len(targets)):
                break
            frontier = nxt
        return found, len(dj) + len(dl)

    # -- trees --
    def _grow(self, a: str) -> _Tree:
        """The tree of ``a`` over the whole cluster (one full search)."""
        tree = _Tree()
        placed, known = self.placed, self.known
        links_of, revolute = self.links_of, self.revolute
        dj, sj, dl, sl = tree.dj, tree.sj, tree.dl, tree.sl
        dj[a], sj[a] = 0, 1
        frontier = [a]
        d = 0
        while frontier:
            nxt: list[str] = []
            if d % 2 == 0:
                for node in frontier:
                    w = sj[node]
                    for x in links_of[node]:
                        if x in placed:
                            if x not in dl:
                                dl[x], sl[x] = d + 1, w
                                nxt.append(x)
                            elif dl[x] == d + 1:
                                sl[x] += w
            else:
                for node in frontier:
                    w = sl[node]
                    for j in revolute[node]:
                        if j in known:
                            if j not in dj:
                                dj[j], sj[j] = d + 1, w
                                nxt.append(j)
                            elif dj[j] == d + 1:
                                sj[j] += w
            d += 1
            frontier = nxt
        self.visits += len(dj) + len(dl)
        return tree

    def link_placed(self, link: str) -> None:
        """Repair the trees after ``link`` joined the placed set."""
        for a in list(self.trees):
            self._repair(a, self.trees[a], link, True)

    def joint_known(self, joint: str) -> None:
        """Repair the trees after ``joint`` joined the known set."""
        for a in list(self.trees):
            self._repair(a, self.trees[a], joint, False)

    def _repair(self, a: str, tree: _Tree, node: str, is_link: bool) -> None:
        """Distances and counts after ``node`` and its edges were added.

        Distances only shrink when a node is added.  The nodes whose distance or
        count changes are settled in increasing new distance (a heap keyed by it,
        the parity telling links from joints), each from its neighbours one layer
        closer, which are final by then; a node that does not change stops the
        repair along that way.
        """
        placed, known = self.placed, self.known
        links_of, revolute = self.links_of, self.revolute
        dj, sj, dl, sl = tree.dj, tree.sj, tree.dl, tree.sl
        near = dj if is_link else dl
        ds = [near[y] for y in (revolute[node] if is_link else links_of[node]) if y in near]
        if not ds:
            return  # not reachable from the source (yet)
        heap = [(min(ds) + 1, node)]
        settled: set[tuple[int, str]] = set()
        work = 0
        while heap:
            d, y = heapq.heappop(heap)
            odd = d % 2
            if (odd, y) in settled:
                continue
            settled.add((odd, y))
            if odd:  # a placed link, from its known centres
                nbrs, dist, sig, far, far_sig = revolute[y], dj, sj, dl, sl
                inside = known
            else:  # a known centre, from its placed links
                nbrs, dist, sig, far, far_sig = links_of[y], dl, sl, dj, sj
                inside = placed
            work += len(nbrs)
            count = 0
            for z in nbrs:
                if z in inside and dist.get(z) == d - 1:
                    count += sig[z]
            if far.get(y) == d and far_sig[y] == count:
                continue  # unchanged: nothing beyond it changes through it
            far[y], far_sig[y] = d, count
            for z in nbrs:
                if z in inside and dist.get(z, d + 2) > d:
                    heapq.heappush(heap, (d + 1, z))
        self.visits += work
        tree.idle += work
        if tree.idle > len(placed) + len(known):
            # repairs cost more than searches would: searches again
            del self.trees[a]
