"""A board recording on disk, defined once: the folder a rig board (real or simulated) writes, one
CSV file per kind of event, and `load_table` to read them back.

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
    recording.json  identity, configuration and final counters (written at the end)

board_tick counts the board's clock, TICK_HZ ticks a second, from its reset; board_time_s is the
same instant in seconds. rig_time_s is the rig clock through the clock sync known at that moment
(sync.csv holds every interval, to convert again later). The writer (rig.board.recorder) flushes
the files after each batch of events, so a recording cut short is still readable.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import NamedTuple

import numpy as np

from analysis.errors import AnalysisError

# The board's clock rate, RIG_TICK_HZ of the board's protocol (rig/board/protocol.h): the analysis
# library reads recordings without the rig, and tests/rig/board checks that the two agree.
TICK_HZ = 2_000_000


class Table(NamedTuple):
    """One CSV file of a recording: its name and its header."""

    name: str
    columns: tuple[str, ...]


TIMED = ("board_tick", "board_time_s", "rig_time_s")
ENCODER = Table("encoder.csv", (*TIMED, "count", "step", "edges"))
PHOTODIODE = Table("photodiode.csv", (*TIMED, "rising"))
PASSAGES = Table("passages.csv", (*TIMED, "start_tick", "end_tick", "peak"))
SAMPLES = Table("samples.csv", (*TIMED, "value"))
LED = Table("led.csv", (*TIMED, "level", "bit"))
STATUS = Table(
    "status.csv",
    (
        "board_tick",
        "board_time_s",
        "stream",
        "rx_frames",
        "rx_corrupt",
        "rx_unknown",
        "rx_overflow",
        "tx_dropped",
        "event_overflow",
        "quad_invalid",
    ),
)
SYNC = Table("sync.csv", ("rig_time_s", "offset_low_s", "offset_high_s", "round_trips", "left_out"))
LINK = Table("link.csv", ("rig_time_s", "kind", "detail"))
TABLES = (ENCODER, PHOTODIODE, PASSAGES, SAMPLES, LED, STATUS, SYNC, LINK)
METADATA = "recording.json"


def load_table(out_dir: Path, name: str) -> dict[str, np.ndarray]:
    """The columns of one of a recording's numeric CSV files, as float64 arrays (an empty cell is
    NaN)."""
    path = Path(out_dir) / name
    try:
        with open(path, newline="") as file:
            rows = list(csv.reader(file))
    except OSError as error:
        raise AnalysisError(f"cannot read {path}: {error.strerror}; is {out_dir} a `rig board record` folder?") from None
    if not rows:
        raise AnalysisError(f"{path} is empty: it should start with a header line")
    header, body = rows[0], rows[1:]
    if any(len(row) != len(header) for row in body):
        raise AnalysisError(f"{path}: a row does not match the header {header}")
    try:
        values = np.array([[float(cell) if cell else np.nan for cell in row] for row in body], dtype=np.float64)
    except ValueError as error:
        raise AnalysisError(f"{path} holds a value that is not a number: {error}") from None
    values = values.reshape(len(body), len(header))
    return {column: values[:, index] for index, column in enumerate(header)}
