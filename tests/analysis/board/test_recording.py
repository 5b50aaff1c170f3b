"""Reading a board recording back: its tables as float columns, and clear errors for a folder that
is not one."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.board.recording import load_table
from analysis.errors import AnalysisError


def test_unreadable_tables_give_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(AnalysisError, match="is .* a `rig board record` folder"):
        load_table(tmp_path, "encoder.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(AnalysisError, match="empty"):
        load_table(tmp_path, "empty.csv")
    (tmp_path / "ragged.csv").write_text("a,b\n1,2\n3\n")
    with pytest.raises(AnalysisError, match="does not match the header"):
        load_table(tmp_path, "ragged.csv")
    (tmp_path / "words.csv").write_text("a\nx\n")
    with pytest.raises(AnalysisError, match="not a number"):
        load_table(tmp_path, "words.csv")
    (tmp_path / "header.csv").write_text("a,b\n")
    assert load_table(tmp_path, "header.csv")["b"].shape == (0,)
