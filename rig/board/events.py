"""What the board reports, as plain values: each event carries its board tick (on the board's full
time line), its board time in seconds and its time on the rig clock. An event's fields are declared
in the order of its recording file's columns (`analysis.board.recording`), in which the recorder
writes them."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class BoardIdentity:
    name: str
    protocol: int
    firmware: str
    tick_hz: int
    cpu_hz: int


@dataclass(frozen=True)
class BoardStatus:
    """The board's own counters (they wrap at 2^16) and the streams it has on."""

    board_tick: int
    board_time: float
    stream: int
    rx_frames: int
    rx_corrupt: int
    rx_unknown: int
    rx_overflow: int
    tx_dropped: int
    event_overflow: int
    quad_invalid: int


@dataclass(frozen=True)
class EncoderEdge:
    """The latest encoder edge: the count went from count - step to count. `edges` is how many
    edges the board saw since its previous report (more than 1 when reporting at a set rate)."""

    board_tick: int
    board_time: float
    rig_time: float
    count: int
    step: int
    edges: int


@dataclass(frozen=True)
class PhotodiodeCrossing:
    board_tick: int
    board_time: float
    rig_time: float
    rising: bool


@dataclass(frozen=True)
class PhotodiodePassage:
    """A bright object passed over the photodiode: the board tick and times are those of the
    centroid (its centre, for a symmetric profile); start and end ticks bound the passage."""

    board_tick: int
    board_time: float
    rig_time: float
    start_tick: int
    end_tick: int
    peak: int


@dataclass(frozen=True)
class PhotodiodeSample:
    board_tick: int
    board_time: float
    rig_time: float
    value: int


@dataclass(frozen=True)
class LedChange:
    """The LED output changed to `level`; `bit` is the blink bit that did it (None: a command)."""

    board_tick: int
    board_time: float
    rig_time: float
    level: int
    bit: int | None


@dataclass(frozen=True)
class ClockSynced:
    """A clock synchronisation finished: the offset interval, the round trips it rests on and the
    round trips left out because they disagreed with those."""

    rig_time: float
    low: float
    high: float
    round_trips: int
    left_out: int


@dataclass(frozen=True)
class LinkChange:
    """The serial link went down ("lost"), came back ("restored") or was given up ("failed")."""

    rig_time: float
    kind: str
    detail: str


BoardEvent = EncoderEdge | PhotodiodeCrossing | PhotodiodePassage | PhotodiodeSample | LedChange | BoardStatus | ClockSynced | LinkChange
