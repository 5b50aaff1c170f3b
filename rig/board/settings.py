"""What the board records, light, so that the command line's options show its defaults and ranges
without the board's link (`rig.board.instrument` records with them)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import Range, check, setting
from rig.errors import ConfigError

DEFAULT_RISE = 512
DEFAULT_FALL = 256


@dataclass(frozen=True)
class BoardSettings:
    """What the board records: encoder reports per second (0: every edge), the photodiode's rising
    and falling thresholds (ADC counts) and every how many raw samples to send (0: none), and how
    often to synchronise the clocks while recording."""

    encoder_rate_hz: float = setting(
        0.0, "Hz", "encoder reports per second; 0 reports every edge (the board's clock bounds it further)",
        Range(0.0, 1e5, True, True), flag="--encoder-rate",
    )  # fmt: skip
    rise: int = setting(
        DEFAULT_RISE, "ADC counts", "photodiode rising threshold, up to the board's ADC's top", Range(1.0, 65535.0, True, True), flag="--rise"
    )
    fall: int = setting(DEFAULT_FALL, "ADC counts", "photodiode falling threshold, below --rise", Range(0.0, 65534.0, True, True), flag="--fall")
    raw_every: int = setting(0, "samples", "also record every n-th raw ADC sample; 0 none", Range(0.0, 65535.0, True, True), flag="--raw-every")
    resync_every_s: float = setting(
        5.0, "seconds", "seconds between clock syncs while recording, at most an hour", Range(0.1, 3600.0, True, True),
        flag="--resync-every",
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError)
