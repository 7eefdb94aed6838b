"""The documentation stands alone: no links out of the repository, no broken links.

README.md, docs/*.md (with the API reference pages docs/api/*.md and the markdown of the
notebook tour), the examples' README, the docstrings the API reference renders and the
benchmarks' docstrings are read by people who have only the repository. A link must
resolve to a file inside it, and the prose must not lean on material the repository
does not contain (project-internal specification paths, issues, task descriptions,
source papers named by an internal file number instead of by author, title, journal
and year).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from project_paths import ROOT

PAGES = sorted(
    [
        ROOT / "README.md",
        ROOT / "catalogs/examples/README.md",
        *(ROOT / "docs").glob("*.md"),
        *(ROOT / "docs/api").glob("*.md"),
    ]
)
NOTEBOOK = ROOT / "docs/tour.ipynb"

# [text](target) and ![alt](target); the target ends at whitespace or ')'.
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
# Forbidden phrases and why: each names something a reader of the repository lacks.
FORBIDDEN = {
    r"\.\./shared": "a path outside the repository",
    r"shared/spec": "the internal specification",
    # (shipped file names such as seed002-ex1-needle-drive.json or "class-iv-seed003" pass)
    r"(?i)(?<![-\"/\w])seed[ -]?0\d\d\b(?![-\"]|\S*\.json)": "a source paper by internal number",
    r"(?i)\bthe seed\b|\bseed's\b": "a source paper by internal name",
    r"(?i)\bthe brief\b": "an internal task description",
    r"(?i)\bfrom the issue\b|\bthe issue's\b": "an internal issue",
    r"(?i)\bissues? #?\d+\b": "an internal issue by number",
    r"(?i)\bnamed by the user\b|\bthe user asked\b": "an internal request",
}


def _rel(page: Path) -> str:
    return page.relative_to(ROOT).as_posix()


def _links(text: str) -> list[str]:
    return [m.group(1) for m in LINK.finditer(text)]


def _is_external(target: str) -> bool:
    return re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target) is not None


def test_pages_found() -> None:
    names = {_rel(p) for p in PAGES}
    assert {"README.md", "docs/contract.md", "docs/references.md"} <= names


@pytest.mark.parametrize("page", PAGES, ids=_rel)
def test_no_reference_to_material_outside_the_repository(page: Path) -> None:
    hits = _hits(_rel(page), page.read_text(encoding="utf-8"))
    assert not hits, "\n".join(hits)


def _hits(name: str, text: str) -> list[str]:
    return [
        f"{name}:{text.count(chr(10), 0, m.start()) + 1}: {why}: {m.group(0)!r}"
        for pattern, why in FORBIDDEN.items()
        for m in re.finditer(pattern, text)
    ]


def test_notebook_markdown_stands_alone() -> None:
    import json

    cells = json.loads(NOTEBOOK.read_text(encoding="utf-8"))["cells"]
    markdown = [c for c in cells if c["cell_type"] == "markdown"]
    assert markdown
    hits = [
        hit
        for k, cell in enumerate(markdown)
        for hit in _hits(f"{_rel(NOTEBOOK)} markdown cell {k}", "".join(cell["source"]))
    ]
    assert not hits, "\n".join(hits)


def _docstrings(path: Path) -> str:
    """All docstrings of a Python file (module, classes, functions), one per paragraph."""
    import ast

    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = [
        n
        for n in ast.walk(tree)
        if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
    ]
    return "\n\n".join(filter(None, (ast.get_docstring(n) for n in nodes)))


@pytest.mark.parametrize(
    "path",
    [p for p in sorted((ROOT / "benchmarks").glob("*.py"))],
    ids=lambda p: p.name,
)
def test_benchmark_docstrings_stand_alone(path: Path) -> None:
    hits = _hits(_rel(path), _docstrings(path))
    assert not hits, "\n".join(hits)


def test_api_reference_docstrings_stand_alone() -> None:
    """The module, class and function docstrings mkdocstrings renders into docs/api."""
    hits = [
        hit
        for path in sorted((ROOT / "src/mjstruct").rglob("*.py"))
        for hit in _hits(_rel(path), _docstrings(path))
    ]
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize("page", PAGES, ids=_rel)
def test_relative_links_resolve_inside_the_repository(page: Path) -> None:
    bad = []
    for target in _links(page.read_text(encoding="utf-8")):
        if _is_external(target) or target.startswith("#"):
            continue
        path = (page.parent / target.split("#", 1)[0]).resolve()
        if not path.is_relative_to(ROOT):
            bad.append(f"{target}: outside the repository")
        elif not path.exists():
            bad.append(f"{target}: no such file")
    assert not bad, f"{_rel(page)}: " + "; ".join(bad)


def test_link_checker_catches_what_it_should(tmp_path: Path) -> None:
    # the patterns must match the defects they exist for, and spare file names
    text = (
        "see [spec](../shared/spec/05-contract.md), seed 002 and Seed-003; "
        "the seed's table; ![fig](img/x.png) and [w](https://example.org); "
        "the budget from issue 4"
    )
    assert _links(text) == ["../shared/spec/05-contract.md", "img/x.png", "https://example.org"]
    found = {why for pattern, why in FORBIDDEN.items() if re.search(pattern, text)}
    assert found == {
        "a path outside the repository",
        "the internal specification",
        "a source paper by internal number",
        "a source paper by internal name",
        "an internal issue by number",
    }
    clean = (
        "catalogs/examples/seed002-ex1-needle-drive.json, class-iv-seed003.json, seeded, "
        'example_path("class-iv-seed003"), example_path("seed002-ex3-excavator")'
    )
    assert not any(re.search(pattern, clean) for pattern in FORBIDDEN)
    assert _is_external("https://example.org") and not _is_external("docs/contract.md")


def test_every_shipped_example_is_described() -> None:
    examples = ROOT / "catalogs" / "examples"
    table = (examples / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"[\w.-]+\.json", table))
    missing = sorted(p.name for p in examples.glob("*.json") if p.name not in listed)
    assert not missing, f"catalogs/examples/README.md does not describe {missing}"


# the source papers whose formulas or methods modules implement: each is cited in a
# numpydoc References section of at least one module
IMPLEMENTED = [
    "Artobolevsky 1988",
    "Assur 1914",
    "Lee & Streinu 2008",
    "MJ structure 2020",
    "Panasenko 2025",
    "Zinchenko",
    "Four-bar clearances",
    "McKay & Piperno 2014",
    "Freudenstein 1955",
    "Burmester 1888",
    "Kavetsky & Geresh",
    "Tsai & Freudenstein",
]


def _module_docstrings() -> dict[str, str]:
    import ast

    out = {}
    for path in sorted((ROOT / "src/mjstruct").rglob("*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        out[_rel(path)] = " ".join(doc.split())
    return out


@pytest.mark.parametrize("key", IMPLEMENTED)
def test_source_papers_cited_by_the_modules_implementing_them(key: str) -> None:
    keys = set(re.findall(r"^\*\*\[([^\]]+)\]\*\*", _references(), re.M))
    assert key in keys
    citing = [
        name
        for name, doc in _module_docstrings().items()
        if "References ----------" in doc
        and f"[{key}] in docs/references.md" in doc.split("References ----------", 1)[1]
    ]
    assert citing, f"no module's References section cites [{key}]"


def _references() -> str:
    return (ROOT / "docs/references.md").read_text(encoding="utf-8")


def test_readme_layout_names_every_module() -> None:
    """README's Layout section names each module of the package (by file stem); the
    command modules of cli/ are covered by "one module per command"."""
    from mjstruct.cli.main import COMMANDS

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    layout = readme.split("## Layout", 1)[1].split("\n## ", 1)[0]
    words = set(re.findall(r"[\w.]+", layout))
    src = ROOT / "src/mjstruct"
    missing = sorted(
        p.relative_to(src).as_posix()
        for p in src.rglob("*.py")
        if p.name != "__init__.py"
        and p.stem not in words
        and p.name not in words
        and not (p.parent.name == "cli" and p.stem in COMMANDS)
    )
    assert not missing, f"README.md Layout does not name {missing}"
    packages = {p.parent.name for p in src.rglob("__init__.py")} - {"mjstruct"}
    assert all(f"{name}/" in layout for name in packages)
