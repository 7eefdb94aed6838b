"""Pins the public API and the CLI commands: changing them must be deliberate."""

from __future__ import annotations

import tomllib
from pathlib import Path

import mjstruct
from mjstruct.cli.main import COMMANDS

ROOT = Path(__file__).resolve().parents[1]

PUBLIC = [
    "Atlas",
    "Chain",
    "assur_atlas",
    "atlas",
    "cells",
    "code_counts",
    "familiar_name",
    "is_admissible",
    "lookup",
    "rigid_subchain",
    "seed_invariants",
    "KinematicsResult",
    "jacobian_at_reference",
    "kinematics",
    "plan_kinematics",
    "read_geometry",
    "AssurGroup",
    "Decomposition",
    "DriverChoice",
    "GenericMobility",
    "assur_groups",
    "driver_choices",
    "generic_dof",
    "generic_mobility",
    "pebble_rank",
    "plot_decomposition",
    "random_mechanism",
    "rigid_components",
    "rigidity",
    "Assortment",
    "Joint",
    "Mechanism",
    "MechanismError",
    "NumericalError",
    "Point",
    "StructuralReport",
    "assortment",
    "canonical_code",
    "code_report",
    "from_link_graph",
    "full_code",
    "incidence_matrix",
    "is_isomorphic",
    "is_planar",
    "link_assortment",
    "loop_assortment",
    "mechanism_from_dict",
    "mechanism_to_dict",
    "mechanism_to_toml",
    "mj_assortment",
    "mj_factor",
    "parse_code",
    "parse_mechanism",
    "read_mechanism",
    "simple_joint_count",
    "structural_code",
    "structural_report",
    "to_networkx",
]

CLI = ["analyze", "assur", "atlas", "cells", "iso", "kinematics", "lookup"]


def test_public_names_pinned():
    assert sorted(mjstruct.__all__) == sorted(PUBLIC)
    for name in PUBLIC:
        assert getattr(mjstruct, name) is not None


def test_cli_commands_pinned():
    assert sorted(COMMANDS) == sorted(CLI)


def test_every_subpackage_is_packaged():
    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {
        ".".join(p.parent.relative_to(ROOT / "src").parts)
        for p in (ROOT / "src" / "mjstruct").rglob("__init__.py")
    }
    assert found <= listed
