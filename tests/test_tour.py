"""docs/tour.ipynb runs top to bottom (nbclient) and shows what it says it shows."""

from __future__ import annotations

import nbformat
from nbclient import NotebookClient

from project_paths import ROOT

TOUR = ROOT / "docs" / "tour.ipynb"


def test_tour_notebook_runs_and_shows_its_results(tmp_path):
    nb = nbformat.read(TOUR, as_version=4)
    assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), (
        "the tour is stored without outputs"
    )
    client = NotebookClient(
        nb, timeout=60, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()  # raises CellExecutionError on any failing cell
    text = "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)
    images = sum(
        "image/png" in o.get("data", {})
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.outputs
    )
    assert "in the catalog: True" in text
    assert "structural invariants agree: True" in text and "isomorphic: False" in text
    assert "4 with MJs allowed" in text
    assert "mechanism class 3" in text and "warnings: none" in text
    assert "same mechanism after the trip: True" in text
    assert images == 5  # every drawing is inline
    assert list(tmp_path.iterdir()) == []  # the tour writes no files
