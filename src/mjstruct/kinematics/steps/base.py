"""What every step kind provides, the registry of kinds, and the state they work on.

Owns the contract between the planner, the evaluation and the step kinds: a
:class:`Step` of a plan (its ``kind`` is a name in :data:`STEP_KINDS`), a
:class:`StepKind` (the description, evaluation over all frames, reference assembly
mode, triangle class and closure equations of one kind), a :class:`PlanRule` (how the
planner finds steps of a family), the planner's :class:`PlanState` (placed links,
known centres, queues of candidates so that propagation stays O(n log n)) and the
evaluation's :class:`Run` (poses over the frames).  The step kinds themselves live in
the sibling modules, one per family; each registers itself here on import.

Examples
--------
>>> from mjstruct.kinematics.steps import STEP_KINDS
>>> sorted(k for k, v in STEP_KINDS.items() if v.has_modes)
['RPR', 'RRP', 'RRR']
>>> Step("RRR", ("2", "3"), joint="B", inputs=("A", "O2")).describe()
'dyad RRR: links 2, 3 from centres A, O2 meet at B (one general triangle)'
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.triangles import Jet, Pose
from mjstruct.mechanism import Mechanism

FloatArray = npt.NDArray[np.float64]
#: assembly mode per dyad step (±1, scalar or per frame)
Modes = Mapping[int, "npt.NDArray[Any] | int"]


def other_link(m: Mechanism, joint: str, link: str) -> str:
    """The link of a two-link ``joint`` that is not ``link`` (:meth:`Mechanism.other_link`)."""
    return m.other_link(joint, link)


@dataclass(frozen=True)
class Step:
    """One step of a plan.

    ``links`` are the links the step places (for a closure: the links whose
    disagreement it measures), ``joint`` the joint it solves or drives, ``inputs`` the
    known joints it starts from, ``base`` the link a driver or guide belongs to,
    ``index`` the driver or unknown number, ``diagonal`` the triangles the triangle
    rule spends to find a dyad's base side across the cluster, ``checks`` the
    triangles that find the same base along the other shortest paths (computed as a
    check).
    """

    kind: str
    links: tuple[str, ...]
    joint: str = ""
    inputs: tuple[str, ...] = ()
    base: str = ""
    index: int = -1
    diagonal: int = 0
    checks: int = 0

    @property
    def step_kind(self) -> StepKind:
        """What this step's kind does (from :data:`STEP_KINDS`)."""
        return STEP_KINDS[self.kind]

    def describe(self) -> str:
        """The step in words."""
        return self.step_kind.template.format(n=self.index + 1, **self.__dict__)

    @property
    def is_closure(self) -> bool:
        """True for a closure equation (no link placed)."""
        return self.step_kind.equations > 0

    @property
    def equations(self) -> int:
        """Closure equations this step contributes."""
        return self.step_kind.equations


@dataclass
class Run:
    """One evaluation of a plan over the frames: inputs and the poses found so far.

    ``poses`` link -> pose (jets over the frames); ``first`` joint -> the first link
    placed that carries it; ``solved`` joint -> jet of a centre a dyad solved directly;
    ``residuals`` the closure equations' jets; ``diag`` step index -> (discriminant,
    signed sine) of a dyad.
    """

    mechanism: Mechanism
    geometry: Geometry
    q: FloatArray
    order: int
    rates: FloatArray
    t: FloatArray
    t1: FloatArray
    t2: FloatArray
    modes: Modes
    poses: dict[str, Pose] = field(default_factory=dict)
    first: dict[str, str] = field(default_factory=dict)
    solved: dict[str, Jet] = field(default_factory=dict)
    residuals: list[Jet] = field(default_factory=list)
    diag: dict[int, tuple[FloatArray, FloatArray]] = field(default_factory=dict)

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.q.shape[0])

    def place(self, link: str, pose: Pose) -> None:
        """Record a link's pose; its joints are first seen on it unless seen before."""
        self.poses[link] = pose
        for jid in self.mechanism.link_joints[link]:
            self.first.setdefault(jid, link)

    def centre(self, joint: str) -> Jet:
        """Jet of a known joint centre."""
        if joint in self.solved:
            return self.solved[joint]
        return self.poses[self.first[joint]].point(self.geometry.centres[joint])

    def mode(self, k: int, reference: int) -> npt.NDArray[Any] | int:
        """Assembly mode of step ``k`` (given, else the reference configuration's)."""
        return self.modes.get(k, reference)


Evaluator = Callable[[Step, int, Run], None]
ReferenceMode = Callable[[Step, Geometry], int]
#: (links whose poses a step reads, joints whose centres it reads)
Reads = Callable[[Step, Mechanism], tuple[tuple[str, ...], tuple[str, ...]]]


@dataclass(frozen=True)
class StepKind:
    """Everything one kind of step does, in one place.

    Attributes
    ----------
    name : the kind as it appears in a plan (``Step.kind``).
    template : the step in words (``str.format`` over the step's fields, ``n`` = index + 1).
    evaluate : computes the step over all frames into a :class:`Run` (exact σ and κ).
    triangle : the triangle class it counts as (``"general"``, ``"right"`` or None).
    equations : closure equations it contributes (0 for a step that places links).
    reference_mode : assembly mode (±1) reproducing the reference configuration, for
        kinds with two assembly modes (None: a unique solution).
    guides : for a line intersection, the two guides whose parallelism leaves the
        step undefined.
    reads : the links and joint centres the step's evaluation reads (so that one step
        can be evaluated with only the steps it depends on); None: every step before.
    """

    name: str
    template: str
    evaluate: Evaluator
    triangle: Literal["general", "right"] | None = None
    equations: int = 0
    reference_mode: ReferenceMode | None = None
    guides: Callable[[Step], tuple[str, str]] | None = None
    reads: Reads | None = None

    @property
    def has_modes(self) -> bool:
        """True when the step has two assembly modes (a branch to choose)."""
        return self.reference_mode is not None


#: the step kinds by name; each family module registers its kinds on import
STEP_KINDS: dict[str, StepKind] = {}


def reads_inputs(s: Step, m: Mechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """What a step reads when it starts from its input centres only."""
    return (), s.inputs


def reads_base_and_first_input(s: Step, m: Mechanism) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """What a step reads when it starts from link ``base`` and its first input centre."""
    return (s.base,), s.inputs[:1]


def register(kind: StepKind) -> StepKind:
    """Add a step kind to :data:`STEP_KINDS` (each name once)."""
    if kind.name in STEP_KINDS:
        raise ValueError(f"step kind {kind.name!r} is registered twice")
    STEP_KINDS[kind.name] = kind
    return kind


# -- planning --------------------------------------------------------------------------

#: what a planning rule examines: the drivers, one link, or one revolute/prismatic joint
Subject = Literal["drivers", "link", "R", "P"]


@dataclass(frozen=True)
class PlanRule:
    """How the planner finds steps of one family.

    ``apply(state, subject)`` tries to add steps for one candidate (a link or a joint
    id; ``""`` for the drivers rule) and returns True when it did.  Rules are tried in
    ``priority`` order (lowest first); the first that succeeds restarts the search.
    A rule's candidates are the links or joints whose neighbourhood changed since it
    last looked (see :class:`PlanState`), smallest file index first.
    """

    name: str
    subject: Subject
    priority: int
    apply: Callable[[PlanState, str], bool]


#: planning rules in priority order; each family module registers its rules on import
PLAN_RULES: list[PlanRule] = []


def register_rule(rule: PlanRule) -> PlanRule:
    """Add a planning rule (kept sorted by priority)."""
    PLAN_RULES.append(rule)
    PLAN_RULES.sort(key=lambda r: r.priority)
    return rule


class Topology:
    """Index tables of a mechanism the planner reads often (built once per plan)."""

    def __init__(self, m: Mechanism, drivers: tuple[str, ...]) -> None:
        self.mechanism = m
        self.drivers = drivers
        self.driver_set = frozenset(drivers)
        self.joint_index = {j.id: k for k, j in enumerate(m.joints)}
        self.link_index = {x: k for k, x in enumerate(m.links)}
        self.kind = {j.id: j.kind for j in m.joints}
        self.revolute = {
            x: tuple(j for j in m.link_joints[x] if self.kind[j] == "R") for x in m.links
        }
        # prismatic joints that are guides (not drivers), per link
        self.guides = {
            x: tuple(j for j in m.link_joints[x] if self.kind[j] == "P" and j not in drivers)
            for x in m.links
        }
        # links of each joint, and how many of them have a guide: a rule that needs
        # two guided links at a joint skips a multiple joint of unguided ones at once
        self.links_of = {j.id: j.links for j in m.joints}
        self.guided = {j.id: sum(1 for x in j.links if self.guides[x]) for j in m.joints}


class PlanState:
    """Placed links and known centres during propagation, with candidate queues.

    A candidate leaves its rule's queue when the rule finds nothing for it, and comes
    back only when something it depends on changes: a link gets its first known centre
    (its joints are queued) or its second (the link is queued), a link is placed (the
    joints of the links that slide on it are queued), or the set of links allowed to
    be placed changes (:meth:`open`).  So every rule's first applicable candidate in
    file order is found without rescanning the mechanism.
    """

    def __init__(self, m: Mechanism, geom: Geometry, topo: Topology) -> None:
        self.m, self.geom, self.topo = m, geom, topo
        self.placed: set[str] = set()
        self.known: set[str] = set()
        self.count: dict[str, int] = dict.fromkeys(m.links, 0)
        # per joint: how many of its links have exactly one known centre (a dyad at an
        # unknown joint needs one; a multiple joint without any is skipped in O(1))
        self.ones: dict[str, int] = dict.fromkeys(topo.links_of, 0)
        self.steps: list[Step] = []
        self.unknowns = 0
        self.allowed: set[str] | None = None
        self.queues: dict[str, list[int]] = {r.name: [] for r in PLAN_RULES}
        self.queued: dict[str, set[int]] = {r.name: set() for r in PLAN_RULES}

    def copy(self) -> PlanState:
        s = PlanState(self.m, self.geom, self.topo)
        s.placed, s.known, s.count = set(self.placed), set(self.known), dict(self.count)
        s.ones = dict(self.ones)
        s.steps, s.unknowns, s.allowed = list(self.steps), self.unknowns, self.allowed
        s.queues = {k: list(v) for k, v in self.queues.items()}
        s.queued = {k: set(v) for k, v in self.queued.items()}
        return s

    @property
    def drivers(self) -> tuple[str, ...]:
        return self.topo.drivers

    # -- queues --
    def _push(self, subject: Subject, index: int) -> None:
        for r in PLAN_RULES:
            if r.subject == subject and index not in self.queued[r.name]:
                self.queued[r.name].add(index)
                heapq.heappush(self.queues[r.name], index)

    def push_link(self, link: str) -> None:
        self._push("link", self.topo.link_index[link])

    def push_joints_of(self, link: str) -> None:
        for j in self.m.link_joints[link]:
            self._push(self.topo.kind[j], self.topo.joint_index[j])  # type: ignore[arg-type]

    def open(self, allowed: set[str] | None) -> None:
        """Allow placing ``allowed`` links (None: all) and queue what they touch."""
        self.allowed = allowed
        for link in self.m.links if allowed is None else sorted(allowed):
            if link not in self.placed:
                self.push_link(link)
                self.push_joints_of(link)

    def pop(self, rule: PlanRule) -> str | None:
        """The next candidate of ``rule`` (smallest file index), or None."""
        heap = self.queues[rule.name]
        if not heap:
            return None
        i = heapq.heappop(heap)
        self.queued[rule.name].discard(i)
        return self.m.links[i] if rule.subject == "link" else self.m.joints[i].id

    # -- state --
    def free(self, link: str) -> bool:
        """Not placed yet, and allowed to be placed now."""
        return link not in self.placed and (self.allowed is None or link in self.allowed)

    def known_on(self, link: str) -> list[str]:
        """Known revolute centres of ``link`` (file order; they are distinct points)."""
        return [j for j in self.topo.revolute[link] if j in self.known]

    def coincide(self, a: str, b: str) -> bool:
        from mjstruct.kinematics.tolerances import COINCIDE

        return abs(self.geom.centres[a] - self.geom.centres[b]) <= COINCIDE * self.geom.scale

    def place(self, link: str, step: Step, used: tuple[str, ...] | list[str]) -> None:
        """Mark ``link`` placed by ``step``, which used the joints ``used``.

        Its other centres already known elsewhere, and its guides on links already
        placed, become closure equations (close-point, close-slide).
        """
        self.placed.add(link)
        for j in self.topo.revolute[link]:
            if j in self.known and j not in used:
                other = next(x for x in self.m.joint(j).links if x in self.placed and x != link)
                self.steps.append(Step("close-point", (link, other), joint=j))
            self._know(j)
        for g in self.topo.guides[link]:
            other = other_link(self.m, g, link)
            if other in self.placed:
                if g not in used:
                    self.steps.append(Step("close-slide", (link, other), joint=g))
            else:
                # the other link may now slide on a placed guide: its dyads are candidates
                self.push_joints_of(other)

    def _know(self, joint: str) -> None:
        if joint in self.known:
            return
        self.known.add(joint)
        for x in self.m.joint(joint).links:
            self.count[x] += 1
            if self.count[x] <= 2:
                step = 1 if self.count[x] == 1 else -1
                for j in self.m.link_joints[x]:
                    self.ones[j] += step
            if self.count[x] == 1:
                self.push_joints_of(x)
            elif self.count[x] == 2:
                self.push_link(x)

    def add(self, step: Step) -> Step:
        self.steps.append(step)
        return step

    # -- triangle counts along the placed cluster --
    def _distances(self, a: str, targets: set[str], full: bool) -> dict[str, tuple[int, int]]:
        """Edges and number of shortest paths from joint ``a`` to ``targets``.

        Breadth first over known centres and placed links; stops after the layer where
        the first target is met unless ``full`` (then: every reachable target).
        """
        if a not in self.known:
            return {}
        if a in targets:
            return {a: (0, 1)}
        # joints and links kept apart (no tuple per node): the same breadth-first
        # counts, a smaller constant on multiple joints of many links
        placed, known = self.placed, self.known
        links_of, revolute = self.topo.links_of, self.topo.revolute
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
        return found

    def paths(self, a: str, b: str) -> tuple[int, int]:
        """(triangles along one shortest path a–b, triangles along the other ones)."""
        hit = self._distances(a, {b}, full=False).get(b)
        if hit is None:
            return 0, 0
        each = max(0, hit[0] // 2 - 1)
        return each, each * (hit[1] - 1)

    def nearest(self, a: str, targets: list[str]) -> int:
        """min over targets of (1 + triangles to reach it); an unreachable one counts 1."""
        if not targets:
            return 1
        found = self._distances(a, set(targets), full=False)
        best = min((max(0, d // 2 - 1) for d, _ in found.values()), default=0)
        if best == 0 or len(found) == len(set(targets)):
            return 1 + best
        # farther than one triangle: an unreachable target would give 1
        everything = self._distances(a, set(targets), full=True)
        return 1 if len(everything) < len(set(targets)) else 1 + best
