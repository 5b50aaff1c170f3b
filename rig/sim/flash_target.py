"""A calibration target's settings, each declared on its field: what the command line's options are
made from, without the simulation's numerical libraries (`rig.sim.flash` films it)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from declared import FRACTION, OPEN_UNIT, Range, check, setting
from rig.errors import ConfigError

FLASH_SOURCES = ("light", "display")


@dataclass(frozen=True)
class FlashTarget:
    """What the camera films instead of the bench (see the module), each setting declared on its
    field; `rig simulate --flash-hz F [--flash-duty D]` or `--flash-display N` makes one."""

    source: str = setting("light", "", "what flashes: a card lit by an LED, or the display full-field", choices=FLASH_SOURCES)
    hz: float = setting(100.0, "Hz", "the LED's flash frequency, at most 10 kHz", Range(0.0, 10000.0, includes_high=True))
    duty: float = setting(0.5, "", "the share of each period the LED is on", OPEN_UNIT)
    phase_s: float = setting(0.0, "seconds", "when the LED's first period starts", Range(-3600.0, 3600.0, True, True))
    level_dn: float = setting(150.0, "digital numbers", "how bright the card films at the frame's centre, the LED on", Range(0.0, 65535.0, includes_high=True))
    vignette: float = setting(0.3, "", "the share of the card's level lost at the frame's corners", FRACTION)
    refreshes: int = setting(2, "refreshes", "the flashing display's period: white for the first half, black for the rest", Range(2.0, 1000.0, True, True))

    def __post_init__(self) -> None:
        check(self, ConfigError, "flash.")

    def display_duty(self) -> float:
        """The share of each period a flashing display shows white."""
        return math.ceil(self.refreshes / 2) / self.refreshes
