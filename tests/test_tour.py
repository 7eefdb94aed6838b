"""docs/tour.ipynb is stored executed (so the docs site and any notebook viewer show its
pictures) and up to date: run again, it prints the same text and shows the same
pictures (the same size within 2 %, and alike block by block: see
:func:`pictures_differ`), and it shows what it says it shows.

After changing the tour or what it prints, store it again with
``python tests/test_tour.py`` (runs it top to bottom and writes the outputs in place).
"""

from __future__ import annotations

import base64
import copy
import io
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


#: pictures are compared in blocks of this many pixels a side (their mean grey)
BLOCK = 8
#: a block differs when its mean grey differs by more than this (of 255) ...
BLOCK_GREY = 16.0
#: ... and two pictures differ when more than this fraction of their blocks do
BLOCKS_DIFFERING = 0.005


def pictures(nb: Any) -> list[bytes]:
    """The PNG pictures a notebook shows, in order."""
    return [
        base64.b64decode(o.data["image/png"])
        for cell in nb.cells
        if cell.cell_type == "code"
        for o in cell.outputs
        if "image/png" in o.get("data", {})
    ]


def pictures_differ(stored: bytes, fresh: bytes) -> str | None:
    """Why two PNGs are not the same picture, or None: a size more than 2 % apart, or
    more than 0.5 % of their 8-pixel blocks with a mean grey more than 16 levels apart
    (anti-aliasing and the fonts of another library version move single pixels; a
    legend moved, an axis in other units or a drawing laid out anew move blocks)."""
    import numpy as np
    from PIL import Image

    a, b = (Image.open(io.BytesIO(x)).convert("L") for x in (stored, fresh))
    if any(abs(p - q) > 0.02 * p for p, q in zip(a.size, b.size, strict=True)):
        return f"size {a.size} stored, {b.size} now"
    b = b.resize(a.size)
    w, h = (n // BLOCK * BLOCK for n in a.size)

    def blocks(image: Any) -> Any:
        g = np.asarray(image, float)[:h, :w]
        return g.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean(axis=(1, 3))

    share = float((np.abs(blocks(a) - blocks(b)) > BLOCK_GREY).mean())
    return f"{share:.1%} of the blocks differ" if share > BLOCKS_DIFFERING else None


def test_pictures_differ_sees_a_moved_legend_and_not_a_shifted_pixel() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def png(legend: str, dx: float = 0.0) -> bytes:
        fig, ax = plt.subplots(figsize=(5, 3))
        ax.plot([0, 1, 2], [0, 1 + dx, 0], label="curve")
        ax.legend(loc=legend)
        out = io.BytesIO()
        fig.savefig(out, format="png", dpi=80)
        plt.close(fig)
        return out.getvalue()

    assert pictures_differ(png("upper left"), png("upper left")) is None
    assert pictures_differ(png("upper left"), png("upper left", 1e-3)) is None
    assert pictures_differ(png("upper left"), png("lower right")) is not None


def test_tour_is_stored_executed_and_up_to_date(tmp_path: Path) -> None:
    stored = nbformat.read(TOUR, as_version=4)
    code = [c for c in stored.cells if c.cell_type == "code"]
    assert all(c.execution_count for c in code), "the tour is stored executed"
    kept = substance(stored)
    assert sum(x == "<picture>" for cell in kept for x in cell) == PICTURES
    fresh = execute(stored, tmp_path)
    assert substance(fresh) == kept, "the stored tour is out of date: python tests/test_tour.py"
    for k, (a, b) in enumerate(zip(pictures(stored), pictures(fresh), strict=True), 1):
        why = pictures_differ(a, b)
        assert why is None, f"picture {k} of the tour is stale ({why}): python tests/test_tour.py"
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
