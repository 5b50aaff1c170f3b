"""Board recordings to latency: the recording format (`recording`), the blink code that puts a
video on the board's clock (`blink_code`), the latency from the photodiode against the encoder
(`photodiode_latency`), and a recording as the camera path's reference (`reference`).

A rig board, real or simulated, writes the recordings (rig.board, rig.sim.board); nothing here
needs the rig.
"""

from analysis.board.blink_code import BlinkAlignment, BlinkSchedule, align_blink_code, lfsr_bits
from analysis.board.photodiode_latency import BoardLatency, estimate_board_latency, estimate_from_recording, plot_board_latency
from analysis.board.recording import load_table
from analysis.board.reference import BoardReference

__all__ = [
    "BlinkAlignment",
    "BlinkSchedule",
    "BoardLatency",
    "BoardReference",
    "align_blink_code",
    "estimate_board_latency",
    "estimate_from_recording",
    "lfsr_bits",
    "load_table",
    "plot_board_latency",
]
