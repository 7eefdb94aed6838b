"""The rigid bodies a decomposition moves: links welded by the driven joints.

This module owns :class:`BodyModel`: a driven joint fixes the relative position of
its first two links, so they act as one body (for a frame joint: the crank joins the
frame); the *initial mechanisms* are ``(driver, base link, driven link)``.  Joints
are kept with the distinct bodies they touch (:data:`LevelJoint`); rigid clusters
solved on the way are merged into new bodies with :meth:`BodyModel.merge`.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                             ("O2", [3, 0])], frame=0)
>>> model = BodyModel(four_bar, ["O1"])
>>> [b.links for b in model.bodies], model.initial
([('0', '1'), ('2',), ('3',)], [('O1', '0', '1')])
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from mjstruct.errors import MechanismError
from mjstruct.mechanism import Joint, Mechanism

LevelJoint = tuple[Joint, list[int]]  # a joint and the distinct bodies it touches


@dataclass(frozen=True)
class Body:
    """Links moving as one; ``root`` stands for the body (the link a group owns)."""

    links: tuple[str, ...]
    root: str


def link_key(x: str) -> tuple[int, str]:
    """Sort key: numeric link ids in numeric order, before the others."""
    return (0, f"{int(x):012d}") if x.isdigit() else (1, x)


class BodyModel:
    """Bodies after welding the driven joints, and the joints between them."""

    def __init__(self, m: Mechanism, drivers: Sequence[str]) -> None:
        if m.frame is None:
            raise MechanismError("frame: the decomposition needs a frame link")
        # driven joints weld their first two links: union-find over those pairs only
        parent: dict[str, str] = {}

        def find(x: str) -> str:
            root = x
            while root in parent:
                root = parent[root]
            while x != root:  # path compression
                parent[x], x = root, parent[x]
            return root

        self.initial: list[tuple[str, str, str]] = []
        driven: set[str] = set()
        for d in drivers:
            a, b = m.joint(d).links[:2]
            self.initial.append((d, a, b))
            driven.add(b)
            ra, rb = find(a), find(b)
            if ra != rb:
                parent[rb] = ra
        groups: dict[str, list[str]] = {}
        for x in m.links:
            groups.setdefault(find(x) if parent else x, []).append(x)
        self.bodies: list[Body] = []
        self.body_of: dict[str, int] = {}
        for members in groups.values():
            if m.frame in members:
                root = m.frame
            else:
                root = next((x for x in members if x not in driven), members[0])
            for x in members:
                self.body_of[x] = len(self.bodies)
            self.bodies.append(Body(tuple(members), root))
        self.frame_body = self.body_of[m.frame]
        self.joints: list[LevelJoint] = []
        body_of = self.body_of
        for j in m.joints:
            if len(j.links) == 2:
                u, v = body_of[j.links[0]], body_of[j.links[1]]
                if u != v:
                    self.joints.append((j, [u, v]))
                continue
            touched = list(dict.fromkeys(body_of[x] for x in j.links))
            if len(touched) >= 2:
                self.joints.append((j, touched))
        self.order = {j.id: k for k, j in enumerate(m.joints)}

    def merge(self, members: Sequence[int], root: str) -> int:
        """A new body made of ``members`` (a rigid cluster); returns its index."""
        links = tuple(sorted((x for b in members for x in self.bodies[b].links), key=link_key))
        self.bodies.append(Body(links, root))
        return len(self.bodies) - 1
