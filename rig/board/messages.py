"""The board's messages as events: each 32-bit tick placed on the board's full time line (SYNC and
STATUS messages carry the full time and anchor it), in board seconds and on the rig clock."""

from __future__ import annotations

from typing import Any, Callable

from rig.board.clock_sync import TickUnwrapper
from rig.board.events import BoardEvent, BoardStatus, EncoderEdge, LedChange, PhotodiodeCrossing, PhotodiodePassage, PhotodiodeSample
from rig.board.protocol import protocol


def status_event(fields: dict[str, Any], tick: int) -> BoardStatus:
    """A STATUS message's fields as an event, at the full board tick `tick`."""
    counters = {name: fields[name] for name in BoardStatus.__dataclass_fields__ if name in fields}
    return BoardStatus(board_tick=tick, board_time=tick / protocol()["RIG_TICK_HZ"], **counters)


class MessageReader:
    """Turns messages from one board into events, in the order they arrive.

    to_rig_time: converts a board time to the rig clock (NaN before the first clock sync).
    """

    def __init__(self, to_rig_time: Callable[[float], float]) -> None:
        self._to_rig_time = to_rig_time
        self._unwrapper = TickUnwrapper()

    def event(self, message_type: int, fields: dict[str, Any]) -> BoardEvent | None:
        """The event a message reports; None for answers to commands and for anchors alone."""
        spec = protocol()
        name = spec.type_names[message_type]
        if name == "RIG_MSG_STATUS":
            tick = self._unwrapper.anchor(fields["epoch"], fields["tick"])
            return status_event(fields, tick) if fields["unsolicited"] else None
        if name == "RIG_MSG_SYNC":
            self._unwrapper.anchor(fields["epoch"], fields["rx_tick"])
            return None
        if name == "RIG_MSG_ENCODER":
            tick, board_time, rig_time = self._times(fields["tick"])
            return EncoderEdge(tick, board_time, rig_time, fields["count"], fields["step"], fields["edges"])
        if name == "RIG_MSG_CROSSING":
            tick, board_time, rig_time = self._times(fields["tick"])
            return PhotodiodeCrossing(tick, board_time, rig_time, bool(fields["rising"]))
        if name == "RIG_MSG_PASSAGE":
            tick, board_time, rig_time = self._times(fields["centroid_tick"])
            start = tick - (fields["centroid_tick"] - fields["start_tick"]) % TickUnwrapper.WRAP
            end = tick + (fields["end_tick"] - fields["centroid_tick"]) % TickUnwrapper.WRAP
            return PhotodiodePassage(tick, board_time, rig_time, start, end, fields["peak"])
        if name == "RIG_MSG_SAMPLE":
            tick, board_time, rig_time = self._times(fields["tick"])
            return PhotodiodeSample(tick, board_time, rig_time, fields["value"])
        if name == "RIG_MSG_LED":
            tick, board_time, rig_time = self._times(fields["tick"])
            bit = None if fields["bit"] == spec["RIG_LED_MANUAL"] else fields["bit"]
            return LedChange(tick, board_time, rig_time, fields["level"], bit)
        return None

    def _times(self, tick32: int) -> tuple[int, float, float]:
        tick = self._unwrapper.unwrap(tick32)
        board_time = tick / protocol()["RIG_TICK_HZ"]
        return tick, board_time, self._to_rig_time(board_time)
