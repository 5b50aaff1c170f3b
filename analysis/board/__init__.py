"""Board recordings to latency: the recording format (`recording`), the blink code that puts a
video on the board's clock (`blink_code`), the latency from the photodiode against the encoder
(`photodiode_latency`), and a recording as the camera path's reference (`reference`).

A rig board, real or simulated, writes the recordings (rig.board, rig.sim.board); nothing here
needs the rig. `photodiode_latency` (with scipy and matplotlib behind it) is imported from its
module, so that using a recording as the camera path's reference does not load them.
"""

from declared.lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "BlinkAlignment": "analysis.board.blink_code",
        "BlinkSchedule": "analysis.board.blink_code",
        "align_blink_code": "analysis.board.blink_code",
        "lfsr_bits": "analysis.board.blink_code",
        "load_table": "analysis.board.recording",
        "BoardReference": "analysis.board.reference",
    },
)

__all__ = [
    "BlinkAlignment",
    "BlinkSchedule",
    "BoardReference",
    "align_blink_code",
    "lfsr_bits",
    "load_table",
]
