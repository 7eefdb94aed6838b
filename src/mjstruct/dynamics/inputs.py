"""The dynamics' boundary: a mechanism, its drivers, geometry and dynamics keys checked once.

Owns :func:`read_inputs`, the one place where a dynamics entry point
(:func:`~mjstruct.dynamics.analysis.dynamic_analysis`,
:func:`~mjstruct.dynamics.time.motion_in_time`) checks what it was given: the
mechanism's type, the driver ids, the reference geometry and the dynamics keys, in
that order, each once.  It hands inward a :class:`~mjstruct.kinematics.model.KinematicModel`
(the validated mechanism, geometry and plan) and the :class:`DynamicsData`; the inner
functions trust both.  Bad dynamics data is named before the planning runs.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> model, data = read_inputs(read_mechanism(example_path("slider-crank-seed000-dynamics")))
>>> model.drivers, data.unknown
(('O1',), 'p')
>>> read_inputs("slider-crank.json")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: mechanism: expected a Mechanism (read a file ...), got str
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from mjstruct.dynamics.data import DynamicsData, read_dynamics
from mjstruct.errors import MechanismError, expect_ids, expect_instance
from mjstruct.kinematics.geometry import geometry_of
from mjstruct.kinematics.model import KinematicModel
from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure.drivers import validate_drivers

__all__ = ["read_inputs"]


def read_inputs(
    mechanism: Mechanism,
    drivers: Iterable[str] | None = None,
    model: KinematicModel | None = None,
    parameters: Mapping[str, float] | None = None,
) -> tuple[KinematicModel, DynamicsData]:
    """The kinematic model and the dynamics data of ``mechanism``, each checked once.

    Parameters
    ----------
    mechanism : a mechanism with geometry and the dynamics keys.
    drivers : the driver joints (default: the file's, or the model's).
    model : a kinematic model of ``mechanism`` to reuse (its drivers are then the
        analysis's: ``drivers`` must be None or the same).
    parameters : values overriding the file's (the unknown included).

    Raises
    ------
    MechanismError
        naming the field or the parameter (``mechanism``, ``drivers``, ``model``,
        ``joints[k].at``, ``inertia.…``, ``loads[k]…``, ``parameters``).
    """
    expect_mechanism(mechanism, "mechanism")
    expect_ids(drivers, "drivers")
    if mechanism.extra.get("gears"):
        raise MechanismError("gears: the dynamics of gear pairs is not modelled yet")
    if model is None:
        geometry = geometry_of(mechanism, validate_drivers(mechanism, drivers, balance=False))
    else:
        expect_instance(model, "model", KinematicModel, "a KinematicModel")
        if model.mechanism is not mechanism and model.mechanism != mechanism:
            raise MechanismError(
                f"model: a kinematic model of {model.mechanism.name or 'another mechanism'!r}, "
                f"not of {mechanism.name or 'this mechanism'!r}"
            )
        if drivers is not None and tuple(drivers) != model.drivers:
            raise MechanismError(
                f"drivers: {', '.join(drivers)} differ from the model's "
                f"({', '.join(model.drivers)}); give drivers or a model built with them"
            )
        geometry = model.geometry
    data = read_dynamics(mechanism, geometry).with_parameters(parameters)
    if model is None:
        model = KinematicModel.from_geometry(mechanism, geometry)
    return model, data
