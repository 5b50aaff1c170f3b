"""The rig board's host side: the microcontroller beside the pendulum (firmware/) reached through
`Microcontroller` over any pyserial URL, its protocol read from protocol.h (shipped in this
package, see protocol.py), clock sync as offset intervals, its events, and `BoardRecorder`, which
writes them as a board recording (the format is analysis.board.recording's)."""

from declared.lazy import lazy_exports

_EXPORTS = {
    "ClockModel": "rig.board.clock_sync",
    "OffsetInterval": "rig.board.clock_sync",
    "BoardIdentity": "rig.board.events",
    "BoardStatus": "rig.board.events",
    "ClockSynced": "rig.board.events",
    "EncoderEdge": "rig.board.events",
    "LedChange": "rig.board.events",
    "LinkChange": "rig.board.events",
    "PhotodiodeCrossing": "rig.board.events",
    "PhotodiodePassage": "rig.board.events",
    "PhotodiodeSample": "rig.board.events",
    "Microcontroller": "rig.board.microcontroller",
    "BoardRecorder": "rig.board.recorder",
}
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
