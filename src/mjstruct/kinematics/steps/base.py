"""What every step kind provides, the registry of kinds, and the state they work on.

Owns the contract between the planner, the evaluation and the step kinds: a
:class:`Step` of a plan (its ``kind`` is a name in :data:`STEP_KINDS`), a
:class:`StepKind` (the description, evaluation over all frames, reference assembly
mode, triangle class and closure equations of one kind), a :class:`PlanRule` (how the
planner finds steps of a family), the planner's :class:`PlanState` (placed links,
known centres, queues of candidates so that propagation stays O(n log n)), the
shortest paths across the placed cluster its triangle counts read
(:class:`ClusterPaths`, kept up to date for a source queried often) and the
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
from functools import cached_property
from typing import Any, Literal, Protocol

import numpy as np
import numpy.typing as npt

from mjstruct.kinematics.geometry import Geometry
from mjstruct.kinematics.tolerances import COINCIDE
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


class LowerEvaluation(Protocol):
    """What a run reads of an evaluation of lower order at its configuration.

    :class:`~mjstruct.kinematics.evaluate.Evaluation` satisfies it; the steps read these
    parts only, so they do not import the evaluation that runs them.
    """

    @property
    def first(self) -> Mapping[str, str]:
        """Joint -> the first link placed that carries it."""

    @property
    def carried(self) -> Mapping[str, Jet]:
        """Joint -> its centre's jet as the steps read it."""

    @property
    def poses(self) -> Mapping[str, Pose]:
        """Link -> its pose over the frames."""

    @property
    def diag(self) -> Mapping[int, tuple[FloatArray, FloatArray]]:
        """Dyad step -> (discriminant, signed sine)."""

    @property
    def solved(self) -> Mapping[str, Jet]:
        """Joint -> jet of a centre a dyad solved directly."""


@dataclass
class Run:
    """One evaluation of a plan over the frames: inputs and the poses found so far.

    ``poses`` link -> pose (jets over the frames); ``first`` joint -> the first link
    placed that carries it; ``solved`` joint -> jet of a centre a dyad solved directly;
    ``residuals`` the closure equations' jets; ``diag`` step index -> (discriminant,
    signed sine) of a dyad.  ``rates`` (drivers) and ``t1``, ``t2`` (frames ×
    unknowns) may carry a leading seed axis (``rates`` seeds × 1 × drivers): the
    derivative jets then broadcast to seeds × frames while the values stay per frame,
    so steps index them on the last axis.
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
    first: FirstLinks = field(init=False)
    solved: dict[str, Jet] = field(default_factory=dict)
    residuals: list[Jet] = field(default_factory=list)
    diag: dict[int, tuple[FloatArray, FloatArray]] = field(default_factory=dict)
    #: joint -> its centre's jet carried by its first link (filled by :meth:`centre`;
    #: a link's pose does not change once placed)
    carried: dict[str, Jet] = field(default_factory=dict)
    #: the first links found by earlier evaluations of the same steps (the placement
    #: order is the plan's: they are the same), given to :attr:`first` to start from
    first_memo: dict[str, str] | None = None
    #: an evaluation at the same configuration (driver values, unknowns, modes) whose
    #: derivatives up to order :attr:`known` hold here too (0: positions; 1: also the
    #: first derivatives, the same rates and t'): the steps that support it compute
    #: only the orders above (the same numbers: the same operations on the same values)
    lower: LowerEvaluation | None = None
    known: int = -1

    def __post_init__(self) -> None:
        self.first = FirstLinks(self.mechanism, self.poses, self.first_memo)

    @property
    def frames(self) -> int:
        """Number of frames."""
        return int(self.q.shape[0])

    def place(self, link: str, pose: Pose) -> None:
        """Record a link's pose; its joints are first seen on it unless seen before."""
        self.poses[link] = pose
        order = self.first.order
        order.setdefault(link, len(order))

    def centre(self, joint: str) -> Jet:
        """Jet of a known joint centre (carried once per evaluation: a closure reads
        the centres its last placement read)."""
        if joint in self.solved:
            return self.solved[joint]
        got = self.carried.get(joint)
        if got is None:
            link = self.first[joint]
            known = None
            if self.lower is not None and self.lower.first.get(joint) == link:
                known = self.lower.carried.get(joint)
            got = self.carried[joint] = self.poses[link].carry(
                self.geometry.centres[joint], None if known is None else known[: self.known + 1]
            )
        return list(got)

    def lower_pose(self, link: str) -> tuple[npt.NDArray[Any], Jet] | None:
        """``r`` and the known θ', θ'' of ``link`` in :attr:`lower` (None: not there)."""
        pose = None if self.lower is None else self.lower.poses.get(link)
        return None if pose is None else (pose.r, pose.w[: self.known])

    def lower_point(
        self, joint: str, k: int
    ) -> tuple[Jet, npt.NDArray[Any], npt.NDArray[Any]] | None:
        """The known orders of a centre dyad step ``k`` solved in :attr:`lower`, with
        the step's discriminant and sine (None: not there)."""
        if self.lower is None or k not in self.lower.diag or joint not in self.lower.solved:
            return None
        disc, det = self.lower.diag[k]
        return self.lower.solved[joint][: self.known + 1], disc, det

    def mode(self, k: int, reference: int) -> npt.NDArray[Any] | int:
        """Assembly mode of step ``k`` (given, else the reference configuration's)."""
        return self.modes.get(k, reference)


class FirstLinks(dict[str, str]):
    """Joint -> the first placed link that carries it (or the link a step names).

    Found when first asked for, from the placement order (the order of ``poses``),
    instead of recording every joint of every link as it is placed: placing a link
    with thousands of joints (a frame carrying many pivots) would cost that per
    evaluation, and branch refinement evaluates small parts of a plan many times.
    """

    def __init__(
        self, mechanism: Mechanism, poses: dict[str, Pose], memo: dict[str, str] | None = None
    ) -> None:
        super().__init__(memo or ())
        self._mechanism, self._poses, self._memo = mechanism, poses, memo
        #: link -> its place in the placement order (kept by :meth:`Run.place`)
        self.order: dict[str, int] = {}

    def __missing__(self, joint: str) -> str:
        order = self.order
        placed = [x for x in self._mechanism.joint(joint).links if x in self._poses]
        if not placed:
            raise KeyError(joint)
        if not all(x in order for x in placed):  # a pose set without Run.place
            order = {x: k for k, x in enumerate(self._poses)}
        link = min(placed, key=order.__getitem__)
        self[joint] = link
        if self._memo is not None:
            self._memo[joint] = link
        return link


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
    #: whether the rule can ever apply to a subject, from the mechanism alone (None:
    #: to any); a subject it cannot is never queued for it
    relevant: Callable[[Topology, str], bool] | None = None


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
        self.joint_ids = tuple(j.id for j in m.joints)
        self.links_of: dict[str, tuple[str, ...]] = {j.id: j.links for j in m.joints}
        prismatic = {j.id for j in m.joints if j.kind == "P"}
        link_joints = m.link_joints
        self.revolute: dict[str, tuple[str, ...]] = {}
        # prismatic joints that are guides (not drivers), per link
        self.guides: dict[str, tuple[str, ...]] = {}
        for x in m.links:
            js = link_joints[x]
            if prismatic:
                self.revolute[x] = tuple(j for j in js if j not in prismatic)
                self.guides[x] = tuple(j for j in js if j in prismatic and j not in drivers)
            else:
                self.revolute[x], self.guides[x] = js, ()
        # how many links of each joint have a guide: a rule that needs two guided
        # links at a joint skips a multiple joint of unguided ones at once
        guides = self.guides
        self.guided = {j.id: sum(1 for x in j.links if guides[x]) for j in m.joints}
        # the drivers as (index, joint, kind, first link, second link)
        self.driver_links = tuple(
            (i, d, m.joint(d).kind, m.joint(d).links[0], m.joint(d).links[1])
            for i, d in enumerate(drivers)
        )
        # what a link queues when its neighbourhood changes: its (index, rules), and
        # (index, rules, id, revolute, links) of each of its joints; the rules are the
        # positions in PLAN_RULES of those that can ever apply to the subject
        by_subject: dict[str, list[tuple[int, Callable[[Topology, str], bool] | None]]] = {
            "link": [],
            "R": [],
            "P": [],
        }
        for k, rule in enumerate(PLAN_RULES):
            if rule.subject != "drivers":
                by_subject[rule.subject].append((k, rule.relevant))
        key: dict[str, tuple[int, tuple[int, ...], str, bool, tuple[str, ...]]] = {}
        for k, j in enumerate(m.joints):
            rules = tuple(r for r, ok in by_subject[j.kind] if ok is None or ok(self, j.id))
            key[j.id] = (k, rules, j.id, j.kind == "R", j.links)
        self.link_key: dict[str, tuple[int, tuple[int, ...]]] = {}
        for k, x in enumerate(m.links):
            rules = tuple(r for r, ok in by_subject["link"] if ok is None or ok(self, x))
            self.link_key[x] = (k, rules)
        self.joint_keys = {x: tuple(key[j] for j in link_joints[x]) for x in m.links}
        self._positions: dict[str, dict[str, int]] = {}

    @cached_property
    def joint_index(self) -> dict[str, int]:
        """Joint id -> its index in the file (for messages)."""
        return {j.id: k for k, j in enumerate(self.mechanism.joints)}

    def position(self, joint: str) -> dict[str, int]:
        """Link -> its place in the joint's list (for a joint of many links)."""
        pos = self._positions.get(joint)
        if pos is None:
            pos = self._positions[joint] = {x: k for k, x in enumerate(self.links_of[joint])}
        return pos


#: shortest-path trees kept at once (each placement updates every tree)
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
    """Shortest paths between known centres across the placed cluster.

    The length and the number of shortest paths from one known joint centre to
    others, alternating known centres and placed links (the triangles a dyad spends
    to find its base side, :meth:`PlanState.paths`).  A query is a breadth-first
    search that stops after the layer of the first target.  A source queried again
    and again across a large cluster (a multiple joint every dyad starts from, whose
    bases all run through the frame) gets a *tree*: its distances and path counts to
    the whole cluster, repaired as links are placed and centres become known, so that
    a query costs a lookup instead of a search.  A tree is built only once searches
    from its source have cost more than the tree, and dropped when keeping it up to
    date costs more than the searches it saves; either way the answers are the same.

    ``placed`` and ``known`` are the planner's own sets (read, never changed here);
    :meth:`link_placed` and :meth:`joint_known` must be called after each addition.
    ``visits`` counts the nodes the searches and repairs touched (the work a plan
    spends on triangle counts).

    Examples
    --------
    >>> links_of = {"A": ("1", "2"), "B": ("2", "3"), "C": ("3", "1")}
    >>> revolute = {"1": ("A", "C"), "2": ("A", "B"), "3": ("B", "C")}
    >>> cp = ClusterPaths(links_of, revolute, placed={"1", "2", "3"}, known={"A", "B", "C"})
    >>> cp.distances("A", {"B"}, full=False)
    {'B': (2, 1)}
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


class PlanState:
    """Placed links and known centres during propagation, with candidate queues.

    A candidate leaves its rule's queue when the rule finds nothing for it, and comes
    back only when something it depends on changes: a link gets its first known centre
    (its joints are queued) or its second (the link is queued), a link is placed (the
    joints of the links that slide on it are queued), or a link becomes allowed to be
    placed (:meth:`open`; it and its joints are queued).  So every rule's first
    applicable candidate in file order is found without rescanning the mechanism, and
    a propagation costs what changed, not the mechanism's size.
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
        # the links every candidate out of the queues was examined with (see open)
        self.opened: set[str] | None = set()
        self.queues: list[list[int]] = [[] for _ in PLAN_RULES]
        self.queued: list[set[int]] = [set() for _ in PLAN_RULES]
        self.pushes = 0  # candidates queued (the propagation's work)
        self.cluster = ClusterPaths(topo.links_of, topo.revolute, self.placed, self.known)

    def copy(self) -> PlanState:
        s = PlanState.__new__(PlanState)
        s.m, s.geom, s.topo = self.m, self.geom, self.topo
        s.placed, s.known, s.count = set(self.placed), set(self.known), dict(self.count)
        s.ones = dict(self.ones)
        s.steps, s.unknowns, s.allowed = list(self.steps), self.unknowns, self.allowed
        s.opened = self.opened
        s.queues = [list(v) for v in self.queues]
        s.queued = [set(v) for v in self.queued]
        s.pushes = 0
        s.cluster = ClusterPaths(self.topo.links_of, self.topo.revolute, s.placed, s.known)
        return s

    @property
    def drivers(self) -> tuple[str, ...]:
        return self.topo.drivers

    # -- queues --
    # a candidate that can never apply again is not queued: a placed link (place), a
    # known revolute joint (its dyads), a guide pair with a placed link (its dyads)
    def push_link(self, link: str) -> None:
        if link in self.placed:
            return
        index, rules = self.topo.link_key[link]
        queues, queued = self.queues, self.queued
        for r in rules:
            if index not in queued[r]:
                queued[r].add(index)
                heapq.heappush(queues[r], index)
                self.pushes += 1

    def push_joints_of(self, link: str) -> None:
        queues, queued, known, placed = self.queues, self.queued, self.known, self.placed
        for index, rules, joint, revolute, links in self.topo.joint_keys[link]:
            if revolute:
                if joint in known:
                    continue
            elif links[0] in placed or links[1] in placed:
                continue
            for r in rules:
                if index not in queued[r]:
                    queued[r].add(index)
                    heapq.heappush(queues[r], index)
                    self.pushes += 1

    def open(self, allowed: set[str] | None) -> None:
        """Allow placing ``allowed`` links (None: all) and queue what they touch.

        Only links newly allowed are queued: a candidate examined before failed for
        want of a link it may place, or of something that queues it when it changes.
        """
        self.allowed = allowed
        before = self.opened
        fresh: list[str] = []
        if before is None:
            pass  # every link was allowed: nothing is new
        elif allowed is None:
            fresh = [x for x in self.m.links if x not in before]
        else:
            fresh = [x for x in allowed if x not in before]
        self.opened = allowed
        for link in fresh:
            if link not in self.placed:
                self.push_link(link)
                self.push_joints_of(link)

    # -- state --
    def free(self, link: str) -> bool:
        """Not placed yet, and allowed to be placed now."""
        return link not in self.placed and (self.allowed is None or link in self.allowed)

    def known_on(self, link: str) -> list[str]:
        """Known revolute centres of ``link`` (file order; they are distinct points)."""
        known = self.known
        return [j for j in self.topo.revolute[link] if j in known]

    def coincide(self, a: str, b: str) -> bool:
        c = self.geom.centres
        return abs(c[a] - c[b]) <= COINCIDE * self.geom.scale

    def place(self, link: str, step: Step, used: tuple[str, ...] | list[str]) -> None:
        """Mark ``link`` placed by ``step``, which used the joints ``used``.

        Its other centres already known elsewhere, and its guides on links already
        placed, become closure equations (close-point, close-slide).
        """
        self.placed.add(link)
        if self.cluster.trees:
            self.cluster.link_placed(link)
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
        if self.cluster.trees:
            self.cluster.joint_known(joint)
        count, ones, link_joints = self.count, self.ones, self.m.link_joints
        for x in self.topo.links_of[joint]:
            c = count[x] = count[x] + 1
            if c == 1:
                for j in link_joints[x]:
                    ones[j] += 1
                self.push_joints_of(x)
            elif c == 2:
                for j in link_joints[x]:
                    ones[j] -= 1
                self.push_link(x)

    def add(self, step: Step) -> Step:
        self.steps.append(step)
        return step

    # -- triangle counts along the placed cluster --
    def paths(self, a: str, b: str) -> tuple[int, int]:
        """(triangles along one shortest path a–b, triangles along the other ones)."""
        hit = self.cluster.distances(a, {b}, full=False).get(b)
        if hit is None:
            return 0, 0
        each = max(0, hit[0] // 2 - 1)
        return each, each * (hit[1] - 1)

    def nearest(self, a: str, targets: list[str]) -> int:
        """min over targets of (1 + triangles to reach it); an unreachable one counts 1."""
        if not targets:
            return 1
        found = self.cluster.distances(a, set(targets), full=False)
        best = min((max(0, d // 2 - 1) for d, _ in found.values()), default=0)
        if best == 0 or len(found) == len(set(targets)):
            return 1 + best
        # farther than one triangle: an unreachable target would give 1
        everything = self.cluster.distances(a, set(targets), full=True)
        return 1 if len(everything) < len(set(targets)) else 1 + best
