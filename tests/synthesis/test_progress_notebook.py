"""The progress bar in a Jupyter kernel: a widget (ipywidgets, the `notebook` extra),
and tqdm raises no warning (without ipywidgets it would warn "IProgress not found")."""

from __future__ import annotations

import nbformat
from nbclient import NotebookClient

CELL = """
import warnings

from mjstruct.synthesis.parallel import ProgressBar

with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    bar = ProgressBar("atlas", enabled=True)
    for k in range(1, 4):
        bar(k, 3)
print("warnings:", [f"{w.category.__name__}: {w.message}" for w in caught])
"""


def test_progress_bar_is_a_widget_without_warnings(tmp_path):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(CELL)]
    client = NotebookClient(
        nb, timeout=60, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = nb.cells[0].outputs
    text = "".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    assert "warnings: []" in text, text
    assert "IProgress" not in text and "TqdmWarning" not in text
    widgets = [
        o for o in outputs if "application/vnd.jupyter.widget-view+json" in o.get("data", {})
    ]
    assert widgets, outputs  # a widget, not a text bar
