"""Board recordings on disk: one CSV file per kind of event, written as the events arrive (the
format is analysis.board.recording's; tests/analysis/board reads it)."""

from __future__ import annotations

import json
import math
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from analysis.board.recording import load_table
from rig.board import BoardRecorder, ClockSynced, EncoderEdge, LedChange, LinkChange, PhotodiodePassage
from rig.board.recorder import FILES
from rig.errors import RigError


def test_events_are_on_disk_after_each_batch(tmp_path: Path) -> None:
    recorder = BoardRecorder(tmp_path / "run")
    recorder.on_event(EncoderEdge(board_tick=4_000_001, board_time=2.0000005, rig_time=10.5, count=-3, step=-1, edges=1))
    recorder.on_event(LedChange(board_tick=10, board_time=5e-6, rig_time=math.nan, level=255, bit=None))
    recorder.on_event(LedChange(board_tick=20, board_time=1e-5, rig_time=8.0, level=0, bit=7))
    recorder.on_event(PhotodiodePassage(board_tick=30, board_time=1.5e-5, rig_time=8.1, start_tick=25, end_tick=35, peak=800))
    recorder.on_event(ClockSynced(rig_time=9.0, low=-1.25, high=-1.2499, round_trips=40, left_out=2))
    recorder.on_event(LinkChange(rig_time=9.5, kind="lost", detail="read failed, 5"))
    recorder.on_batch_end()
    encoder = load_table(tmp_path / "run", "encoder.csv")
    assert encoder["board_tick"].tolist() == [4_000_001] and encoder["board_time_s"][0] == 2.0000005
    assert (encoder["count"][0], encoder["step"][0], encoder["rig_time_s"][0]) == (-3, -1, 10.5)
    led = load_table(tmp_path / "run", "led.csv")
    assert np.isnan(led["bit"][0]) and led["bit"][1] == 7 and np.isnan(led["rig_time_s"][0])
    assert load_table(tmp_path / "run", "passages.csv")["end_tick"].tolist() == [35]
    assert load_table(tmp_path / "run", "sync.csv")["left_out"].tolist() == [2]
    assert (tmp_path / "run" / "link.csv").read_text().splitlines()[1] == '9.5,lost,"read failed, 5"'
    assert recorder.counts["led.csv"] == 2
    recorder.write_metadata({"identity": {"name": "rig-avr"}})
    recorder.close()
    assert json.loads((tmp_path / "run" / "recording.json").read_text())["identity"]["name"] == "rig-avr"
    assert {name for name, _ in FILES.values()} <= {path.name for path in (tmp_path / "run").iterdir()}


def test_a_folder_with_a_recording_is_not_overwritten(tmp_path: Path) -> None:
    BoardRecorder(tmp_path).close()
    with pytest.raises(RigError, match="already holds a board recording"):
        BoardRecorder(tmp_path)


@pytest.mark.parametrize("kind", list(FILES), ids=lambda kind: kind.__name__)
def test_each_event_is_written_field_by_field_under_its_columns(kind: type, tmp_path: Path) -> None:
    names = [field.name for field in fields(kind)]
    columns = FILES[kind].columns
    # A field is its column, maybe with its unit (seconds) and, for the sync interval, "offset_".
    assert len(names) == len(columns)
    for name, column in zip(names, columns):
        assert column in (name, f"{name}_s", f"offset_{name}_s")
    values = {field.name: (True if field.type == "bool" else f"x{i}" if field.type == "str" else i + 0.5 if field.type == "float" else i)
              for i, field in enumerate(fields(kind))}  # fmt: skip
    recorder = BoardRecorder(tmp_path)
    recorder.on_event(kind(**values))
    recorder.close()
    row = (tmp_path / FILES[kind].name).read_text().splitlines()[1].split(",")
    assert row == [str(int(value) if isinstance(value, bool) else value) for value in values.values()]
