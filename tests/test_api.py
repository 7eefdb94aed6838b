"""Pins the public API and the CLI commands: changing them must be deliberate."""

from __future__ import annotations

import tomllib

import mjstruct
from mjstruct.cli.main import COMMANDS
from project_paths import ROOT

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
    "DynamicsResult",
    "dynamic_analysis",
    "KinematicModel",
    "KinematicsResult",
    "Motion",
    "jacobian_at_reference",
    "singular_analysis",
    "SingularAnalysis",
    "SingularPosition",
    "classify_singular_frames",
    "fourbar_theory",
    "FourBar",
    "plot_ms_diagram",
    "plot_singular_zones",
    "kinematic_analysis",
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
    "scene_at",
    "scene_over_cycle",
    "draw_scene",
    "write_drawing",
    "write_animation",
    "draw_chart",
    "write_atlas_sheet",
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
    "mechanism_from_pyslvs",
    "mechanism_to_pyslvs",
    "mechanism_from_graphml",
    "mechanism_to_graphml",
    "mechanism_from_node_link",
    "mechanism_to_node_link",
    "DesignResult",
    "synthesize",
    "explore",
    "planetary_synthesis",
    "planetary_ratio_range",
    "egt_atlas",
]

CLI = [
    "analyze",
    "animate",
    "assur",
    "atlas",
    "cells",
    "convert",
    "draw",
    "dynamics",
    "iso",
    "kinematics",
    "lookup",
    "planetary",
    "plot",
    "singular",
    "synthesize",
]


def test_public_names_pinned():
    assert sorted(mjstruct.__all__) == sorted(PUBLIC)
    for name in PUBLIC:
        assert getattr(mjstruct, name) is not None


SUBPACKAGES = (
    "cli",
    "design",
    "dynamics",
    "exchange",
    "gears",
    "kinematics",
    "plot",
    "singular",
    "structure",
    "synthesis",
)


def test_subpackage_list_complete():
    found = {p.parent.name for p in (ROOT / "src/mjstruct").glob("*/__init__.py")}
    assert found == set(SUBPACKAGES)


def test_exports_are_stable_callables():
    """Each export is one object on every access (no subpackage shadows it) and is a class
    (CamelCase names) or a function (lower-case names), as the API reference documents."""
    import importlib
    import inspect

    first = {name: getattr(mjstruct, name) for name in PUBLIC}
    # importing every subpackage must not change what a public name refers to
    for sub in SUBPACKAGES:
        importlib.import_module(f"mjstruct.{sub}")
    for name in PUBLIC:
        obj = getattr(mjstruct, name)
        assert obj is first[name], name
        assert obj is getattr(mjstruct, name), name
        assert not inspect.ismodule(obj), f"{name} is a module"
        if name[0].isupper():
            assert inspect.isclass(obj), f"{name} is not a class"
        else:
            assert inspect.isfunction(obj), f"{name} is not a function"


def _init_tree():
    import ast

    return ast.parse((ROOT / "src/mjstruct/__init__.py").read_text())


def test_type_checking_block_matches_exports():
    """The typed re-exports (for type checkers) name exactly the lazy exports."""
    import ast

    block = next(n for n in _init_tree().body if isinstance(n, ast.If))
    typed = {
        a.name: n.module for n in block.body if isinstance(n, ast.ImportFrom) for a in n.names
    }
    assert typed == mjstruct._EXPORTS


def test_all_is_a_literal_list_of_the_exports():
    """`__all__` is a literal list (a type checker reads it statically; names listed in it
    are explicit re-exports under `mypy --strict`) holding exactly the lazy exports."""
    import ast

    assign = next(
        n
        for n in _init_tree().body
        if isinstance(n, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in n.targets)
    )
    assert isinstance(assign.value, ast.List)
    literal = [ast.literal_eval(e) for e in assign.value.elts]
    assert literal == mjstruct.__all__
    assert sorted(literal) == sorted(mjstruct._EXPORTS)
    assert len(set(literal)) == len(literal)


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


def test_no_private_names_imported_across_modules():
    """Library modules and benchmarks use each other's public names only."""
    import ast

    bad = []
    for path in sorted([*(ROOT / "src").rglob("*.py"), *(ROOT / "benchmarks").glob("*.py")]):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("mjstruct"):
                bad += [
                    f"{path.relative_to(ROOT)}: {node.module}.{a.name}"
                    for a in node.names
                    if a.name.startswith("_") and not a.name.startswith("__")
                ]
    assert not bad, bad


# modules that still define their own array aliases (owned by work in progress); the
# list only shrinks: new code imports them from mjstruct.typing
OWN_ARRAY_ALIASES = {
    "dynamics/analysis.py",
    "dynamics/data.py",
    "dynamics/equation.py",
    "dynamics/matrices.py",
    "dynamics/reactions.py",
    "dynamics/time.py",
    "dynamics/time_terms.py",
    "kinematics/branches.py",
    "kinematics/checks.py",
    "kinematics/closure.py",
    "kinematics/evaluate.py",
    "kinematics/jacobian.py",
    "kinematics/model.py",
    "kinematics/result.py",
    "kinematics/solver.py",
    "kinematics/steps/base.py",
}


def test_array_aliases_have_one_home():
    """`FloatArray` and friends are defined in mjstruct.typing, not again per module."""
    import re

    src = ROOT / "src/mjstruct"
    alias = re.compile(r"^\w+Array(?:: TypeAlias)? = npt\.NDArray\[", re.M)
    defining = {
        p.relative_to(src).as_posix()
        for p in src.rglob("*.py")
        if alias.search(p.read_text(encoding="utf-8"))
    }
    assert "typing.py" in defining
    assert defining - {"typing.py"} <= OWN_ARRAY_ALIASES, sorted(defining - OWN_ARRAY_ALIASES)
