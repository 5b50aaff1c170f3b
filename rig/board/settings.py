"""What the board records, light, so that the command line's options show its defaults without the
board's link (`rig.board.instrument` records with them)."""

from __future__ import annotations

from dataclasses import dataclass

DEFAULT_RISE = 512
DEFAULT_FALL = 256


@dataclass(frozen=True)
class BoardSettings:
    """What the board records: encoder reports per second (0: every edge), the photodiode's rising
    and falling thresholds (ADC counts) and every how many raw samples to send (0: none), and how
    often to synchronise the clocks while recording."""

    encoder_rate_hz: float = 0.0
    rise: int = DEFAULT_RISE
    fall: int = DEFAULT_FALL
    raw_every: int = 0
    resync_every_s: float = 5.0
