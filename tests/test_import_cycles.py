"""No import circle between any two modules of the package, inside a unit or across.

The layer contract (``lint-imports``, ``test_layers.py``) keeps the units in layers but
leaves out imports under ``if TYPE_CHECKING:`` and says nothing about modules inside one
unit.  This test reads every module's imports itself: top-level, inside functions and
type-only alike, and fails on any circle, naming its modules.  A type-only circle says
two modules know each other's insides: one of them should own the interface (a
``Protocol``, as :mod:`mjstruct.kinematics.model_view`) and the other depend on it.
"""

from __future__ import annotations

import ast
from pathlib import Path

import networkx as nx

from project_paths import ROOT


def module_names(src: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every module under ``src``."""
    out = {}
    for p in src.rglob("*.py"):
        parts = list(p.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def import_graph(src: Path, root: str = "mjstruct") -> nx.DiGraph:
    """Module -> the package's modules it imports, wherever the import statement is."""
    mods = module_names(src)
    graph = nx.DiGraph()
    graph.add_nodes_from(m for m in mods if m.split(".")[0] == root)
    for name, path in mods.items():
        if name.split(".")[0] != root:
            continue
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                # ``from pkg import module`` imports the module, else the package
                targets = [
                    f"{base}.{a.name}" if f"{base}.{a.name}" in mods else base for a in node.names
                ]
            else:
                continue
            for target in targets:
                while target and target not in mods:
                    target = target.rpartition(".")[0]
                if target and target != name and target.split(".")[0] == root:
                    graph.add_edge(name, target)
    return graph


def circles(graph: nx.DiGraph) -> list[list[str]]:
    """The groups of modules that import each other round a circle (sorted)."""
    return sorted(sorted(c) for c in nx.strongly_connected_components(graph) if len(c) > 1)


def test_no_import_circle_in_the_package():
    found = circles(import_graph(ROOT / "src"))
    assert not found, "import circles (type-only and function-level imports count): " + "; ".join(
        " <-> ".join(c) for c in found
    )


def test_a_type_only_circle_is_found(tmp_path):
    # the check itself: a circle closed only through ``if TYPE_CHECKING:`` is reported
    pkg = tmp_path / "mjstruct" / "unit"
    pkg.mkdir(parents=True)
    (tmp_path / "mjstruct" / "__init__.py").write_text("")
    (pkg / "__init__.py").write_text("")
    (pkg / "model.py").write_text("from mjstruct.unit.evaluate import evaluate\n")
    (pkg / "evaluate.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n"
        "    from mjstruct.unit.model import Model\n"
        "def evaluate():\n"
        "    from . import helpers\n"
    )
    (pkg / "helpers.py").write_text("")
    assert circles(import_graph(tmp_path)) == [["mjstruct.unit.evaluate", "mjstruct.unit.model"]]
    (pkg / "evaluate.py").write_text("def evaluate():\n    from . import helpers\n")
    assert circles(import_graph(tmp_path)) == []
