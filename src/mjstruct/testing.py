"""Random mechanisms with a known structure, for property tests and benchmarks.

This module owns :func:`random_mechanism`: a one-DOF mechanism grown from a crank by
dyads, triads and class-IV groups, so that its Assur decomposition is known by
construction; :func:`random_geometry`, a random reference configuration for it; and
:func:`shared_crank`, the size-scaling family of the kinematics benchmarks and tests.
It is not part of the pinned public API.

>>> m = random_mechanism(3, seed=2)
>>> m.frame, m.drivers
('0', ('J0',))
"""

from __future__ import annotations

import cmath
import math
import random
from dataclasses import dataclass, field

from mjstruct.mechanism import Mechanism


@dataclass
class _Grower:
    rng: random.Random
    joints: list[tuple[str, list[str], str]] = field(default_factory=list)
    placed: list[str] = field(default_factory=list)
    used: set[str] = field(default_factory=set)  # joints extended by the current group
    count: int = 0
    #: chance that a new external joint is prismatic
    slider: float = 0.1
    #: the one placed link every external pin of the current group lands on (None: any)
    host: str | None = None

    def new_link(self) -> str:
        self.count += 1
        return str(self.count)

    def attach(self, link: str, mj: float, known: int) -> None:
        """Pin ``link`` to a placed link: on a known R joint (making an MJ) or anew."""
        # a joint takes one link of a group at most: two would be pinned twice together
        rj = [j for j in self.joints[:known] if j[2] == "R" and j[0] not in self.used]
        if rj and self.rng.random() < mj:
            joint = self.rng.choice(rj)
            joint[1].append(link)
            self.used.add(joint[0])
        else:
            kind = "P" if self.rng.random() < self.slider else "R"
            on = self.rng.choice(self.placed) if self.host is None else self.host
            self.joints.append((f"J{len(self.joints)}", [on, link], kind))

    def pin(self, a: str, b: str) -> None:
        self.joints.append((f"J{len(self.joints)}", [a, b], "R"))


def random_mechanism(
    groups: int,
    seed: int = 0,
    mj: float = 0.3,
    slider: float = 0.1,
    hang: float = 0.0,
) -> Mechanism:
    """A random one-DOF mechanism grown from a crank by dyads, triads and class-IV groups.

    External pins land on an existing revolute joint with probability ``mj`` (which
    makes multiple joints); a new external joint is prismatic with probability
    ``slider`` (a triad's leg on a slider, a dyad RRP, ...); with probability ``hang``
    every new external joint of a group lands on one placed link (a group hanging on
    one link: rigid relative to it when all its pins are new).  Frame ``"0"``, driver
    ``"J0"``.  The defaults draw the same mechanisms as before these options existed.

    >>> m = random_mechanism(5, seed=1)
    >>> m.frame, m.drivers, len(m.links) > 10
    ('0', ('J0',), True)
    >>> m = random_mechanism(3, seed=1, slider=1.0, mj=0.0)
    >>> sum(j.kind == "P" for j in m.joints) > 0
    True
    """
    g = _Grower(random.Random(seed), placed=["0"], slider=slider)
    crank = g.new_link()
    g.joints.append(("J0", ["0", crank], "R"))
    g.placed.append(crank)
    for _ in range(groups):
        known = len(g.joints)  # joints whose position is known before this group
        g.used.clear()
        # drawn only when asked for, so that the default stream is unchanged
        g.host = g.rng.choice(g.placed) if hang > 0 and g.rng.random() < hang else None
        kind = g.rng.random()
        if kind < 0.6:  # dyad
            a, b = g.new_link(), g.new_link()
            g.attach(a, mj, known)
            g.attach(b, mj, known)
            g.pin(a, b)
            new = [a, b]
        elif kind < 0.85:  # triad: ternary base and three legs
            base = g.new_link()
            legs = [g.new_link() for _ in range(3)]
            for leg in legs:
                g.pin(base, leg)
                g.attach(leg, mj, known)
            new = [base, *legs]
        else:  # class IV: two ternary links and two binary links in a 4-contour
            t1, b1, t2, b2 = (g.new_link() for _ in range(4))
            g.pin(t1, b1)
            g.pin(b1, t2)
            g.pin(t2, b2)
            g.pin(b2, t1)
            g.attach(t1, mj, known)
            g.attach(t2, mj, known)
            new = [t1, b1, t2, b2]
        g.placed += new
    return Mechanism.build(
        [(jid, links, kind) for jid, links, kind in g.joints],
        frame="0",
        drivers=["J0"],
        name=f"random-{groups}-{seed}",
    )


def shared_crank(k: int) -> Mechanism:
    """k Grashof crank-rockers on one crank O1-A: 2 + 2k links, A one multiple joint of
    k + 1 links, the rocker pivots on the unit circle.

    >>> len(shared_crank(3).links)
    8
    """
    from mjstruct.io import mechanism_from_dict

    a0 = 0.25 * cmath.exp(0.3j)
    joints: list[dict[str, object]] = [
        {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
        {"id": "A", "links": ["1", *[f"c{i}" for i in range(k)]], "at": [a0.real, a0.imag]},
    ]
    for i in range(k):
        o2 = cmath.exp(2j * math.pi * i / k)
        b = o2 + 0.8j * o2
        joints.append({"id": f"B{i}", "links": [f"c{i}", f"r{i}"], "at": [b.real, b.imag]})
        joints.append({"id": f"O2_{i}", "links": [f"r{i}", "0"], "at": [o2.real, o2.imag]})
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def random_geometry(m: Mechanism, seed: int) -> Mechanism:
    """``m`` with every joint at a random point of the square [-1, 1]² (and every
    slider's axis a random direction), drawn from ``seed``.

    >>> m = random_geometry(random_mechanism(2, seed=4), seed=4)
    >>> all(j.at is not None and max(map(abs, j.at)) <= 1 for j in m.joints)
    True
    """
    import numpy as np

    from mjstruct.io import mechanism_from_dict, mechanism_to_dict

    rng = np.random.default_rng(seed)
    d = mechanism_to_dict(m)
    for j in d["joints"]:
        j["at"] = [float(x) for x in rng.uniform(-1, 1, 2)]
        if j.get("type", "R") == "P":
            j["axis"] = [float(x) for x in rng.uniform(-1, 1, 2)]
    return mechanism_from_dict(d)
