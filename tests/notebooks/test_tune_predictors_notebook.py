"""CI runs the tuning notebook on its small default data, top to bottom, without errors: the tuning,
the default predictor's state over a recording, the choice cross-validated by person and scene, and
the headroom of linear predictors fitted on the other people."""

from pathlib import Path

import nbformat
from nbclient import NotebookClient

NOTEBOOK = Path(__file__).resolve().parents[2] / "notebooks" / "tune_predictors.ipynb"


def test_tune_predictors_notebook_runs():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(notebook, timeout=180, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()
    printed = "".join(
        output.get("text", "") for cell in notebook.cells if cell.cell_type == "code" for output in cell.get("outputs", [])
    )
    assert "kalman-cv (tuned)" in printed and "slerp" in printed
    assert "tracker noise measured:" in printed and "it trusts" in printed and "adaptive / slerp: angle" in printed
    assert "leave one person out" in printed and "cross-validated geometric mean over persons:" in printed
    assert "questpro_walk/user101" in printed and "leave one scene out" in printed
    assert "headroom geometric mean over persons, shared:" in printed and "headroom geometric mean over persons, per axis:" in printed
    assert any("image/png" in output.get("data", {}) for cell in notebook.cells for output in cell.get("outputs", []))
