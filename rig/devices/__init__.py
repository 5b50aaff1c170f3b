"""The rig's devices. The microcontroller beside the pendulum (firmware/) is reached through
`Microcontroller`; its protocol comes from firmware/include/protocol.h (see protocol.py)."""

from rig.devices.blink_code import BlinkAlignment, BlinkSchedule, align_blink_code
from rig.devices.board_events import (
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
from rig.devices.clock_sync import ClockModel, OffsetInterval
from rig.devices.microcontroller import Microcontroller
from rig.devices.photodiode_latency import BoardLatency, estimate_board_latency, estimate_from_recording
from rig.devices.recording import BoardRecorder

__all__ = [
    "BlinkAlignment",
    "BlinkSchedule",
    "BoardIdentity",
    "BoardLatency",
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
    "align_blink_code",
    "estimate_board_latency",
    "estimate_from_recording",
]
