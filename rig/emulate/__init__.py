"""Tracker emulators for tests and demos (`rig emulate-tracker`), never used by a real run.

An emulated tracker measures the simulated pendulum or a recorded trace (motion.py), encodes each
record as a profile says (encode.py), damages and delays records on demand (faults.py), and sends
them through a pseudo-terminal, a TCP socket or an LSL outlet (sinks.py) at a fixed rate, logging
what became of every record (streamer.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from rig.devices.trackers.profile import load_profile
from rig.emulate.encode import RecordEncoder
from rig.emulate.faults import ByteFaults, FaultPlan
from rig.emulate.motion import Motion
from rig.emulate.sinks import LslSink, PtySink, TcpSink
from rig.emulate.streamer import SENT_COLUMNS, SentCounts, Sink, stream
from rig.errors import ConfigError
from rig.records import CsvRecord

# The emulated device's clock starts here (s) when it starts sending, and runs `drift_ppm` fast.
DEVICE_EPOCH_S = 100.0


@dataclass(frozen=True)
class EmulatorConfig:
    """One emulated tracker: where it sends (a pty link path, a TCP port, or an LSL name), what,
    how fast, for how long, with which faults."""

    transport: str
    address: str
    rate_hz: float = 1000.0
    duration_s: float = 10.0
    profile: str = "binary-pose"
    trace: Path | None = None
    faults: FaultPlan = FaultPlan()
    seed: int = 0
    drift_ppm: float = 0.0
    log: Path | None = None

    def __post_init__(self) -> None:
        if not 1.0 <= self.rate_hz <= 10000.0:
            raise ConfigError(f"--rate {self.rate_hz:g}: an emulated tracker sends 1 to 10000 records a second")
        if self.transport == "lsl" and self.faults.damages_bytes:
            raise ConfigError("an LSL stream carries no bytes to damage: corrupt, drop and garbage are serial faults")


def make_sink(config: EmulatorConfig) -> Sink:
    if config.transport == "lsl":
        return LslSink(config.address, config.rate_hz, source_id=f"rig-emulator-{config.address}")
    profile = load_profile(config.profile)
    if profile.format == "hid":
        raise ConfigError(f"profile {profile.name} is a HID profile; a serial emulator sends text or binary records")
    faults = ByteFaults(config.faults, config.seed)
    if config.transport == "pty":
        return PtySink(Path(config.address), RecordEncoder(profile), faults)
    try:
        port = int(config.address)
    except ValueError:
        raise ConfigError(f"--tcp {config.address!r}: expected a port number (0: any free port)") from None
    return TcpSink(port, RecordEncoder(profile), faults)


def run_emulator(config: EmulatorConfig, sink: Sink, on_event: Callable[[str], None]) -> SentCounts:
    """Streams `config` through `sink` (from make_sink), logging every record's fate to config.log."""
    motion = Motion(config.rate_hz, config.duration_s, config.trace)
    if config.transport == "lsl":
        device_clock: Callable[[float], float] = lambda t: t
    else:
        started = time.monotonic()
        device_clock = lambda t: DEVICE_EPOCH_S + (t - started) * (1.0 + config.drift_ppm * 1e-6)
    log = CsvRecord(config.log, SENT_COLUMNS, overwrite=True, flush_each_row=False) if config.log else None
    try:
        return stream(motion, sink, config.duration_s, config.faults, device_clock, log, on_event)
    finally:
        if log is not None:
            log.close()
