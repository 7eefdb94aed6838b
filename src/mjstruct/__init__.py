"""mjstruct: structural and topological analysis of planar linkages with multiple joints.

The core is graph-centred: a :class:`Mechanism` is a bipartite link–joint graph that
keeps multiple joints whole.  Heavy modules (kinematics, dynamics, plotting) are
imported only when used; names below are resolved lazily.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

_EXPORTS: dict[str, str] = {
    "Mechanism": "mjstruct.mechanism",
    "Joint": "mjstruct.mechanism",
    "Point": "mjstruct.mechanism",
    "MechanismError": "mjstruct.errors",
    "NumericalError": "mjstruct.errors",
    "read_mechanism": "mjstruct.io",
    "parse_mechanism": "mjstruct.io",
    "mechanism_from_dict": "mjstruct.io",
    "mechanism_to_dict": "mjstruct.io",
    "mechanism_to_toml": "mjstruct.io",
    "from_link_graph": "mjstruct.io",
    "to_networkx": "mjstruct.io",
    "Assortment": "mjstruct.structure.assortments",
    "assortment": "mjstruct.structure.assortments",
    "link_assortment": "mjstruct.structure.assortments",
    "mj_assortment": "mjstruct.structure.assortments",
    "mj_factor": "mjstruct.structure.assortments",
    "simple_joint_count": "mjstruct.structure.assortments",
    "loop_assortment": "mjstruct.structure.loops",
    "is_planar": "mjstruct.structure.loops",
    "canonical_code": "mjstruct.structure.isomorphism",
    "is_isomorphic": "mjstruct.structure.isomorphism",
    "incidence_matrix": "mjstruct.structure.incidence",
    "structural_code": "mjstruct.structure.codes",
    "full_code": "mjstruct.structure.codes",
    "parse_code": "mjstruct.structure.codes",
    "structural_report": "mjstruct.report",
    "code_report": "mjstruct.report",
    "StructuralReport": "mjstruct.report",
    "assur_groups": "mjstruct.structure.assur",
    "driver_choices": "mjstruct.structure.assur",
    "AssurGroup": "mjstruct.structure.assur",
    "Decomposition": "mjstruct.structure.assur",
    "DriverChoice": "mjstruct.structure.assur",
    "random_mechanism": "mjstruct.structure.assur",
    "generic_mobility": "mjstruct.structure.generic_mobility",
    "GenericMobility": "mjstruct.structure.generic_mobility",
    "pebble_rank": "mjstruct.structure.pebble",
    "generic_dof": "mjstruct.structure.pebble",
    "rigid_components": "mjstruct.structure.pebble",
    "rigidity": "mjstruct.structure.pebble",
    "plot_decomposition": "mjstruct.plot.assur",
    "kinematics": "mjstruct.kinematics.solver",
    "KinematicsResult": "mjstruct.kinematics.solver",
    "plan_kinematics": "mjstruct.kinematics.planner",
    "read_geometry": "mjstruct.kinematics.geometry",
    "jacobian_at_reference": "mjstruct.kinematics.jacobian",
    "atlas": "mjstruct.synthesis.atlas",
    "Atlas": "mjstruct.synthesis.atlas",
    "Chain": "mjstruct.synthesis.atlas",
    "assur_atlas": "mjstruct.synthesis.assur_atlas",
    "cells": "mjstruct.synthesis.cells",
    "code_counts": "mjstruct.synthesis.cells",
    "lookup": "mjstruct.synthesis.catalog",
    "is_admissible": "mjstruct.synthesis.admissibility",
    "rigid_subchain": "mjstruct.synthesis.admissibility",
    "familiar_name": "mjstruct.synthesis.names",
    "seed_invariants": "mjstruct.structure.invariants",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'mjstruct' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
