"""What the evaluation and the closure read of a kinematic model: a small interface.

Owns :class:`ModelView`, the protocol that
:class:`~mjstruct.kinematics.model.KinematicModel` satisfies.  The model builds on the
evaluation, the closure and the branch tracking; they in turn read only these parts of
a model (its mechanism, geometry, plan, drivers, reference driver values, the steps'
dependencies and the first links of a placement).  Typing them against this protocol,
not the model class, keeps the dependency one way: the model knows them, they do not
know the model.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from mjstruct.kinematics.geometry import Geometry
    from mjstruct.kinematics.planner import Plan
    from mjstruct.mechanism import Mechanism
    from mjstruct.typing import FloatArray


class ModelView(Protocol):
    """The parts of a kinematic model that the evaluation and the closure read."""

    @property
    def mechanism(self) -> Mechanism:
        """The link–joint graph with its geometry."""

    @property
    def geometry(self) -> Geometry:
        """The reference configuration."""

    @property
    def plan(self) -> Plan:
        """The triangle steps and closure unknowns for the chosen drivers."""

    @property
    def step_dependencies(self) -> tuple[tuple[int, ...], ...]:
        """For each step, the earlier steps it reads."""

    @property
    def drivers(self) -> tuple[str, ...]:
        """The driving joints, in the plan's order."""

    @property
    def q_ref(self) -> FloatArray:
        """The drivers' values at the reference configuration."""

    def first_links(self, only: tuple[int, ...] | None, upto: int | None) -> dict[str, str]:
        """Joint -> the first link placed that carries it, for the steps evaluated."""
