"""What an emulated tracker is told beyond the simulated tracker's settings, light, so that
`rig emulate-tracker`'s parser declares it without loading the emulator (numpy, LSL)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import Flag, Range, setting


@dataclass(frozen=True)
class ReaderWait:
    """How long an emulator waits for a reader before it ends."""

    idle_timeout_s: float = setting(
        60.0, "seconds", "end when no reader has connected this long after the emulator is ready",
        Range(0.0, 86400.0, False, True), flag=Flag("--idle-timeout", metavar="SECONDS"),
    )  # fmt: skip
