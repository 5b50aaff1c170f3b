"""A board recording on disk: one CSV file per kind of event, written as the events arrive.

    encoder.csv     board_tick, board_time_s, rig_time_s, count, step, edges
    photodiode.csv  board_tick, board_time_s, rig_time_s, rising
    passages.csv    board_tick, board_time_s, rig_time_s, start_tick, end_tick, peak (the tick and
                    times of a passage's centroid)
    samples.csv     board_tick, board_time_s, rig_time_s, value
    led.csv         board_tick, board_time_s, rig_time_s, level, bit (empty: set by command)
    status.csv      board_tick, board_time_s, stream, rx_frames, rx_corrupt, rx_unknown,
                    rx_overflow, tx_dropped, event_overflow, quad_invalid (the 2 Hz heartbeat)
    sync.csv        rig_time_s, offset_low_s, offset_high_s, round_trips, left_out
    link.csv        rig_time_s, kind, detail
    recording.json  identity, configuration and final counters (written by the command)

board_time_s is the board's own clock; rig_time_s the rig clock through the clock sync known at
that moment (sync.csv holds every interval, to convert again later). Files are flushed after each
batch the link delivers, so nothing received is lost if the run stops.
"""

from __future__ import annotations

import csv
import json
from dataclasses import fields
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from rig.devices.board_events import (
    BoardEvent,
    BoardStatus,
    ClockSynced,
    EncoderEdge,
    LedChange,
    LinkChange,
    PhotodiodeCrossing,
    PhotodiodePassage,
    PhotodiodeSample,
)
from rig.errors import RigError

TIMED = ["board_tick", "board_time_s", "rig_time_s"]
FILES: dict[type, tuple[str, list[str]]] = {
    EncoderEdge: ("encoder.csv", TIMED + ["count", "step", "edges"]),
    PhotodiodeCrossing: ("photodiode.csv", TIMED + ["rising"]),
    PhotodiodePassage: ("passages.csv", TIMED + ["start_tick", "end_tick", "peak"]),
    PhotodiodeSample: ("samples.csv", TIMED + ["value"]),
    LedChange: ("led.csv", TIMED + ["level", "bit"]),
    BoardStatus: ("status.csv", ["board_tick", "board_time_s"] + [f.name for f in fields(BoardStatus)][2:]),
    ClockSynced: ("sync.csv", ["rig_time_s", "offset_low_s", "offset_high_s", "round_trips", "left_out"]),
    LinkChange: ("link.csv", ["rig_time_s", "kind", "detail"]),
}
METADATA = "recording.json"


def _time(value: float) -> str:
    return f"{value:.9f}"


def _row(event: BoardEvent) -> list[Any]:
    if isinstance(event, EncoderEdge):
        return [event.board_tick, _time(event.board_time), _time(event.rig_time), event.count, event.step, event.edges]
    if isinstance(event, PhotodiodeCrossing):
        return [event.board_tick, _time(event.board_time), _time(event.rig_time), int(event.rising)]
    if isinstance(event, PhotodiodePassage):
        return [event.board_tick, _time(event.board_time), _time(event.rig_time), event.start_tick, event.end_tick, event.peak]
    if isinstance(event, PhotodiodeSample):
        return [event.board_tick, _time(event.board_time), _time(event.rig_time), event.value]
    if isinstance(event, LedChange):
        bit = "" if event.bit is None else event.bit
        return [event.board_tick, _time(event.board_time), _time(event.rig_time), event.level, bit]
    if isinstance(event, BoardStatus):
        values = [getattr(event, f.name) for f in fields(BoardStatus)]
        return [values[0], _time(values[1])] + values[2:]
    if isinstance(event, ClockSynced):
        return [_time(event.rig_time), _time(event.low), _time(event.high), event.round_trips, event.left_out]
    return [_time(event.rig_time), event.kind, event.detail]


class BoardRecorder:
    """Listens to a Microcontroller and writes its events into `out_dir` (see the module docstring).
    Refuses a folder that already holds a recording, so none is overwritten."""

    def __init__(self, out_dir: Path) -> None:
        self.out_dir = Path(out_dir)
        existing = [name for name, _ in FILES.values() if (self.out_dir / name).exists()]
        if existing:
            raise RigError(f"{self.out_dir} already holds a board recording ({existing[0]}): choose another --out")
        try:
            self.out_dir.mkdir(parents=True, exist_ok=True)
            self._files: dict[type, TextIO] = {kind: open(self.out_dir / name, "w", newline="") for kind, (name, _) in FILES.items()}
        except OSError as error:
            raise RigError(f"cannot write the recording in {self.out_dir}: {error}") from None
        self._writers = {kind: csv.writer(file) for kind, file in self._files.items()}
        for kind, (_, header) in FILES.items():
            self._writers[kind].writerow(header)
        self.counts: dict[str, int] = {name: 0 for name, _ in FILES.values()}

    def on_event(self, event: BoardEvent) -> None:
        kind = type(event)
        self._writers[kind].writerow(_row(event))
        self.counts[FILES[kind][0]] += 1

    def on_batch_end(self) -> None:
        for file in self._files.values():
            file.flush()

    def write_metadata(self, metadata: dict[str, Any]) -> None:
        try:
            (self.out_dir / METADATA).write_text(json.dumps(metadata, indent=2) + "\n")
        except OSError as error:
            raise RigError(f"cannot write {self.out_dir / METADATA}: {error}") from None

    def close(self) -> None:
        for file in self._files.values():
            file.close()


def load_table(out_dir: Path, name: str) -> dict[str, np.ndarray]:
    """The columns of one of a recording's numeric CSV files, as float64 arrays (an empty cell is
    NaN)."""
    path = Path(out_dir) / name
    try:
        with open(path, newline="") as file:
            rows = list(csv.reader(file))
    except OSError as error:
        raise RigError(f"cannot read {path}: {error.strerror}; is {out_dir} a `rig board record` folder?") from None
    if not rows:
        raise RigError(f"{path} is empty: it should start with a header line")
    header, body = rows[0], rows[1:]
    if any(len(row) != len(header) for row in body):
        raise RigError(f"{path}: a row does not match the header {header}")
    try:
        values = np.array([[float(cell) if cell else np.nan for cell in row] for row in body], dtype=np.float64)
    except ValueError as error:
        raise RigError(f"{path} holds a value that is not a number: {error}") from None
    values = values.reshape(len(body), len(header))
    return {column: values[:, index] for index, column in enumerate(header)}
