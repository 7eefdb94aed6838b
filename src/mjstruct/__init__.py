"""mjstruct: structural and topological analysis of planar linkages with multiple joints.

The core is graph-centred: a :class:`Mechanism` is a bipartite link–joint graph that
keeps multiple joints whole.  Heavy modules (kinematics, dynamics, plotting) are
imported only when used; names below are resolved lazily.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"


def _svg_of(obj: object) -> str | None:
    """Notebook pictures come from the drawings, imported at the first picture."""
    from mjstruct.plot.notebook import svg_of

    return svg_of(obj)


importlib.import_module("mjstruct.display").set_svg_renderer(_svg_of)


def _name_singular_frames(r: Any, frames: Any) -> list[str | None]:
    """The kinematics' flagged frames named by the singular-positions unit (above it),
    imported only when a frame is flagged."""
    from mjstruct.singular.analysis import name_flagged_frames

    return name_flagged_frames(r, frames)


importlib.import_module("mjstruct.singular_seam").set_singular_namer(_name_singular_frames)

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
    "mechanism_from_pyslvs": "mjstruct.exchange.pyslvs",
    "mechanism_to_pyslvs": "mjstruct.exchange.pyslvs",
    "mechanism_from_graphml": "mjstruct.exchange.graph_formats",
    "mechanism_to_graphml": "mjstruct.exchange.graph_formats",
    "mechanism_from_node_link": "mjstruct.exchange.graph_formats",
    "mechanism_to_node_link": "mjstruct.exchange.graph_formats",
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
    "generic_mobility": "mjstruct.structure.generic_mobility",
    "GenericMobility": "mjstruct.structure.generic_mobility",
    "pebble_rank": "mjstruct.structure.pebble",
    "generic_dof": "mjstruct.structure.pebble",
    "rigid_components": "mjstruct.structure.pebble",
    "rigidity": "mjstruct.structure.pebble",
    "plot_decomposition": "mjstruct.plot.assur",
    "scene_at": "mjstruct.plot.drawing",
    "scene_over_cycle": "mjstruct.plot.drawing",
    "draw_scene": "mjstruct.plot.drawing",
    "write_drawing": "mjstruct.plot.drawing",
    "write_animation": "mjstruct.plot.animation",
    "draw_chart": "mjstruct.plot.charts",
    "write_atlas_sheet": "mjstruct.plot.atlas_sheet",
    "explore": "mjstruct.plot.explorer",
    "dynamic_analysis": "mjstruct.dynamics.analysis",
    "DynamicsResult": "mjstruct.dynamics.analysis",
    "kinematic_analysis": "mjstruct.kinematics.solver",
    "KinematicsResult": "mjstruct.kinematics.solver",
    "KinematicModel": "mjstruct.kinematics.model",
    "Motion": "mjstruct.kinematics.model",
    "plan_kinematics": "mjstruct.kinematics.planner",
    "read_geometry": "mjstruct.kinematics.geometry",
    "jacobian_at_reference": "mjstruct.kinematics.jacobian",
    "singular_analysis": "mjstruct.singular.analysis",
    "SingularAnalysis": "mjstruct.singular.analysis",
    "SingularPosition": "mjstruct.singular.analysis",
    "classify_singular_frames": "mjstruct.singular.analysis",
    "fourbar_theory": "mjstruct.singular.fourbar",
    "FourBar": "mjstruct.singular.fourbar",
    "plot_ms_diagram": "mjstruct.plot.ms_diagram",
    "plot_singular_zones": "mjstruct.plot.ms_diagram",
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
    "synthesize": "mjstruct.design.api",
    "DesignResult": "mjstruct.design.result",
    "planetary_synthesis": "mjstruct.gears.planetary",
    "planetary_ratio_range": "mjstruct.gears.planetary",
    "egt_atlas": "mjstruct.gears.atlas",
}

# a literal list so that type checkers read it; tests/test_api.py keeps it equal to _EXPORTS
__all__ = [
    "Assortment",
    "AssurGroup",
    "Atlas",
    "Chain",
    "Decomposition",
    "DesignResult",
    "DriverChoice",
    "DynamicsResult",
    "FourBar",
    "GenericMobility",
    "Joint",
    "KinematicModel",
    "KinematicsResult",
    "Mechanism",
    "MechanismError",
    "Motion",
    "NumericalError",
    "Point",
    "SingularAnalysis",
    "SingularPosition",
    "StructuralReport",
    "assortment",
    "assur_atlas",
    "assur_groups",
    "atlas",
    "canonical_code",
    "cells",
    "classify_singular_frames",
    "code_counts",
    "code_report",
    "draw_chart",
    "draw_scene",
    "driver_choices",
    "dynamic_analysis",
    "egt_atlas",
    "explore",
    "familiar_name",
    "fourbar_theory",
    "from_link_graph",
    "full_code",
    "generic_dof",
    "generic_mobility",
    "incidence_matrix",
    "is_admissible",
    "is_isomorphic",
    "is_planar",
    "jacobian_at_reference",
    "kinematic_analysis",
    "link_assortment",
    "lookup",
    "loop_assortment",
    "mechanism_from_dict",
    "mechanism_from_graphml",
    "mechanism_from_node_link",
    "mechanism_from_pyslvs",
    "mechanism_to_dict",
    "mechanism_to_graphml",
    "mechanism_to_node_link",
    "mechanism_to_pyslvs",
    "mechanism_to_toml",
    "mj_assortment",
    "mj_factor",
    "parse_code",
    "parse_mechanism",
    "pebble_rank",
    "plan_kinematics",
    "planetary_ratio_range",
    "planetary_synthesis",
    "plot_decomposition",
    "plot_ms_diagram",
    "plot_singular_zones",
    "read_geometry",
    "read_mechanism",
    "rigid_components",
    "rigid_subchain",
    "rigidity",
    "scene_at",
    "scene_over_cycle",
    "seed_invariants",
    "simple_joint_count",
    "singular_analysis",
    "structural_code",
    "structural_report",
    "synthesize",
    "to_networkx",
    "write_animation",
    "write_atlas_sheet",
    "write_drawing",
]

if TYPE_CHECKING:  # what a type checker sees; tests/test_api.py keeps it equal to _EXPORTS
    from mjstruct.design.api import (
        synthesize,
    )
    from mjstruct.design.result import (
        DesignResult,
    )
    from mjstruct.dynamics.analysis import (
        DynamicsResult,
        dynamic_analysis,
    )
    from mjstruct.errors import (
        MechanismError,
        NumericalError,
    )
    from mjstruct.exchange.graph_formats import (
        mechanism_from_graphml,
        mechanism_from_node_link,
        mechanism_to_graphml,
        mechanism_to_node_link,
    )
    from mjstruct.exchange.pyslvs import (
        mechanism_from_pyslvs,
        mechanism_to_pyslvs,
    )
    from mjstruct.gears.atlas import egt_atlas
    from mjstruct.gears.planetary import (
        planetary_ratio_range,
        planetary_synthesis,
    )
    from mjstruct.io import (
        from_link_graph,
        mechanism_from_dict,
        mechanism_to_dict,
        mechanism_to_toml,
        parse_mechanism,
        read_mechanism,
        to_networkx,
    )
    from mjstruct.kinematics.geometry import (
        read_geometry,
    )
    from mjstruct.kinematics.jacobian import (
        jacobian_at_reference,
    )
    from mjstruct.kinematics.model import (
        KinematicModel,
        Motion,
    )
    from mjstruct.kinematics.planner import (
        plan_kinematics,
    )
    from mjstruct.kinematics.solver import (
        KinematicsResult,
        kinematic_analysis,
    )
    from mjstruct.mechanism import (
        Joint,
        Mechanism,
        Point,
    )
    from mjstruct.plot.animation import (
        write_animation,
    )
    from mjstruct.plot.assur import (
        plot_decomposition,
    )
    from mjstruct.plot.atlas_sheet import (
        write_atlas_sheet,
    )
    from mjstruct.plot.charts import (
        draw_chart,
    )
    from mjstruct.plot.drawing import (
        draw_scene,
        scene_at,
        scene_over_cycle,
        write_drawing,
    )
    from mjstruct.plot.explorer import (
        explore,
    )
    from mjstruct.plot.ms_diagram import (
        plot_ms_diagram,
        plot_singular_zones,
    )
    from mjstruct.report import (
        StructuralReport,
        code_report,
        structural_report,
    )
    from mjstruct.singular.analysis import (
        SingularAnalysis,
        SingularPosition,
        classify_singular_frames,
        singular_analysis,
    )
    from mjstruct.singular.fourbar import (
        FourBar,
        fourbar_theory,
    )
    from mjstruct.structure.assortments import (
        Assortment,
        assortment,
        link_assortment,
        mj_assortment,
        mj_factor,
        simple_joint_count,
    )
    from mjstruct.structure.assur import (
        AssurGroup,
        Decomposition,
        DriverChoice,
        assur_groups,
        driver_choices,
    )
    from mjstruct.structure.codes import (
        full_code,
        parse_code,
        structural_code,
    )
    from mjstruct.structure.generic_mobility import (
        GenericMobility,
        generic_mobility,
    )
    from mjstruct.structure.incidence import (
        incidence_matrix,
    )
    from mjstruct.structure.invariants import (
        seed_invariants,
    )
    from mjstruct.structure.isomorphism import (
        canonical_code,
        is_isomorphic,
    )
    from mjstruct.structure.loops import (
        is_planar,
        loop_assortment,
    )
    from mjstruct.structure.pebble import (
        generic_dof,
        pebble_rank,
        rigid_components,
        rigidity,
    )
    from mjstruct.synthesis.admissibility import (
        is_admissible,
        rigid_subchain,
    )
    from mjstruct.synthesis.assur_atlas import (
        assur_atlas,
    )
    from mjstruct.synthesis.atlas import (
        Atlas,
        Chain,
        atlas,
    )
    from mjstruct.synthesis.catalog import (
        lookup,
    )
    from mjstruct.synthesis.cells import (
        cells,
        code_counts,
    )
    from mjstruct.synthesis.names import (
        familiar_name,
    )


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'mjstruct' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
