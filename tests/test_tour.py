"""docs/tour.ipynb is stored executed (so the docs site and any notebook viewer show its
pictures) and up to date: run again, it prints the same text and shows a picture
wherever the stored copy does, and it shows what it says it shows.

After changing the tour or what it prints, store it again with
``python tests/test_tour.py`` (runs it top to bottom and writes the outputs in place).
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path
from typing import Any

import nbformat
from nbclient import NotebookClient

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run as a script too
from project_paths import ROOT

TOUR = ROOT / "docs" / "tour.ipynb"
PICTURES = 6


def execute(nb: Any, where: Path) -> Any:
    """``nb`` run top to bottom in directory ``where`` (a fresh copy; raises on a failing
    cell), without the timing metadata that would change on every run."""
    fresh = copy.deepcopy(nb)
    for cell in fresh.cells:
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    client = NotebookClient(
        fresh, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(where)}}
    )
    client.execute()
    for cell in fresh.cells:
        cell.metadata.pop("execution", None)
    return fresh


def substance(nb: Any) -> list[list[str]]:
    """Per code cell, what it shows: each text output (stripped of trailing spaces and
    blank lines) and ``"<picture>"`` for each image; the images' bytes differ with the
    library versions."""
    out = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        shown: list[str] = []
        streams: list[str] = []  # raw text of the stream now being read
        for o in cell.outputs:
            if o.output_type == "stream":
                # one stream arrives in pieces cut anywhere (flush timing): join the raw
                # text first, then normalise the lines
                if shown and shown[-1].startswith(f"{o.name}: "):
                    streams[-1] += o.text
                else:
                    shown.append(f"{o.name}: ")
                    streams.append(o.text)
                lines = [x.rstrip() for x in streams[-1].splitlines()]
                shown[-1] = f"{o.name}: " + "\n".join(x for x in lines if x)
                continue
            if "image/png" in o.get("data", {}):
                shown.append("<picture>")
            elif "text/plain" in o.get("data", {}):
                shown.append(o.data["text/plain"])
            else:
                shown.append(o.output_type)
        out.append(shown)
    return out


def test_tour_is_stored_executed_and_up_to_date(tmp_path: Path) -> None:
    stored = nbformat.read(TOUR, as_version=4)
    code = [c for c in stored.cells if c.cell_type == "code"]
    assert all(c.execution_count for c in code), "the tour is stored executed"
    kept = substance(stored)
    assert sum(x == "<picture>" for cell in kept for x in cell) == PICTURES
    fresh = execute(stored, tmp_path)
    assert substance(fresh) == kept, "the stored tour is out of date: python tests/test_tour.py"
    assert list(tmp_path.iterdir()) == []  # the tour writes no files
    text = "\n".join(x for cell in kept for x in cell)
    assert "stderr" not in text  # no warning printed
    assert "in the catalog: True" in text
    assert "structural invariants agree: True" in text and "isomorphic: False" in text
    assert "4 with MJs allowed" in text
    assert "Watt II six-bar: frame link 4, 5" in text and "Stephenson III six-bar" in text
    assert "mechanism class 3" in text and "warnings: none" in text
    assert "drawn at q = 1.26 rad and q = 3.36 rad" in text  # the titles say what is drawn
    assert "same mechanism after the trip: True" in text
    # drawn by the package: scenes, chains, charts (no drawing code of its own)
    sources = "\n".join(c.source for c in code)
    assert "draw_scene" in sources and "draw_chain(" in sources and "draw_chart" in sources
    assert "def " not in sources


def test_the_docs_site_renders_the_stored_tour() -> None:
    """mkdocs-jupyter shows the stored outputs (the strict site build runs in CI)."""
    import yaml

    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    plugins = {
        k: v for p in config["plugins"] for k, v in (p if isinstance(p, dict) else {p: {}}).items()
    }
    assert plugins["mkdocs-jupyter"]["execute"] is False
    assert "tour.ipynb" in plugins["mkdocs-jupyter"]["include"]
    assert any(isinstance(e, dict) and "tour.ipynb" in e.values() for e in config["nav"])


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as where:
        nb = execute(nbformat.read(TOUR, as_version=4), Path(where))
    nbformat.write(nb, TOUR)
    print(f"wrote {TOUR.relative_to(ROOT)} ({sum(map(len, substance(nb)))} outputs)")
