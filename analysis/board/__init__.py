"""Board recordings to latency: the recording format (`recording`), the blink code that puts a
video on the board's clock (`blink_code`), the latency from the photodiode against the encoder
(`photodiode_latency`), and a recording as the camera path's reference (`reference`).

A rig board, real or simulated, writes the recordings (rig.board, rig.sim.board); nothing here
needs the rig. `photodiode_latency` (with scipy and matplotlib behind it) is imported from its
module, so that using a recording as the camera path's reference does not load them.
"""

from analysis.board.blink_code import BlinkAlignment, BlinkSchedule, align_blink_code, lfsr_bits
from analysis.board.recording import load_table
from analysis.board.reference import BoardReference

__all__ = [
    "BlinkAlignment",
    "BlinkSchedule",
    "BoardReference",
    "align_blink_code",
    "lfsr_bits",
    "load_table",
]
