"""The rig board's host side: the microcontroller beside the pendulum (firmware/) reached through
`Microcontroller` over any pyserial URL, its protocol read from protocol.h (shipped in this
package, see protocol.py), clock sync as offset intervals, its events, and `BoardRecorder`, which
writes them as a board recording (the format is analysis.board.recording's)."""

from rig.board.clock_sync import ClockModel, OffsetInterval
from rig.board.events import (
    BoardIdentity,
    BoardStatus,
    ClockSynced,
    EncoderEdge,
    LedChange,
    LinkChange,
    PhotodiodeCrossing,
    PhotodiodePassage,
    PhotodiodeSample,
)
from rig.board.microcontroller import Microcontroller
from rig.board.recorder import BoardRecorder

__all__ = [
    "BoardIdentity",
    "BoardRecorder",
    "BoardStatus",
    "ClockModel",
    "ClockSynced",
    "EncoderEdge",
    "LedChange",
    "LinkChange",
    "Microcontroller",
    "OffsetInterval",
    "PhotodiodeCrossing",
    "PhotodiodePassage",
    "PhotodiodeSample",
]
