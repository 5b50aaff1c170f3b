"""Writes a board recording as the events arrive: one CSV file per kind of event, in the format
analysis.board.recording defines (the file names and columns come from there), through the rig's
one CSV writer, rig.writers.CsvRecord. Files are flushed after each batch the link delivers, so
nothing received is lost if the run stops.
"""

from __future__ import annotations

import json
from dataclasses import astuple
from pathlib import Path
from typing import Any

from analysis.board.recording import ENCODER, LED, LINK, METADATA, PASSAGES, PHOTODIODE, SAMPLES, STATUS, SYNC, TABLES, Table
from rig.board.events import (
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
from rig.writers import CsvRecord

# The file each kind of event goes to.
FILES: dict[type, Table] = {
    EncoderEdge: ENCODER,
    PhotodiodeCrossing: PHOTODIODE,
    PhotodiodePassage: PASSAGES,
    PhotodiodeSample: SAMPLES,
    LedChange: LED,
    BoardStatus: STATUS,
    ClockSynced: SYNC,
    LinkChange: LINK,
}


def _row(event: BoardEvent) -> list[Any]:
    """The event's cells: its fields, declared in the order of its file's columns (a flag as 0 or 1)."""
    return [int(value) if isinstance(value, bool) else value for value in astuple(event)]


class BoardRecorder:
    """Listens to a Microcontroller (or a simulated board) and writes its events into `out_dir`.
    Refuses a folder that already holds a recording, so none is overwritten."""

    def __init__(self, out_dir: Path) -> None:
        self.out_dir = Path(out_dir)
        existing = [table.name for table in TABLES if (self.out_dir / table.name).exists()]
        if existing:
            raise RigError(f"{self.out_dir} already holds a board recording ({existing[0]}): choose another --out")
        try:
            self.out_dir.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise RigError(f"cannot write the recording in {self.out_dir}: {error}") from None
        self._records: dict[type, CsvRecord] = {}
        try:
            for kind, table in FILES.items():
                self._records[kind] = CsvRecord(self.out_dir / table.name, table.columns, flush_each_row=False)
        except RigError:
            self.close()
            raise

    @property
    def counts(self) -> dict[str, int]:
        """Events written so far, by file name."""
        return {record.path.name: record.rows for record in self._records.values()}

    def on_event(self, event: BoardEvent) -> None:
        self._records[type(event)].write(_row(event))

    def on_batch_end(self) -> None:
        for record in self._records.values():
            record.flush()

    def write_metadata(self, metadata: dict[str, Any]) -> None:
        try:
            (self.out_dir / METADATA).write_text(json.dumps(metadata, indent=2) + "\n")
        except OSError as error:
            raise RigError(f"cannot write {self.out_dir / METADATA}: {error}") from None

    def close(self) -> None:
        for record in self._records.values():
            record.close()
