"""Tracker emulators for tests and demos (`rig emulate-tracker`), never used by a real run.

An emulated tracker is the simulated tracker (`rig.sim.tracker.measure`: the simulated pendulum, or
a recorded trace played in a loop, with its noise, transport delay, jitter, dropouts and faults in
time) sent in real time: each record encoded as a profile says (encode.py), its bytes damaged on
demand (`rig.sim.tracker_faults.ByteFaults`), through a pseudo-terminal, a TCP socket or an LSL
outlet (sinks.py), logging what became of every record (streamer.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from declared import check, like
from predictors import quaternion, read_trace
from rig.devices.trackers.default_profiles import SERIAL as DEFAULT_PROFILE
from rig.devices.trackers.profile import load_profile
from rig.emulate.encode import RecordEncoder
from rig.emulate.sinks import LslSink, PtySink, TcpSink
from rig.emulate.streamer import SENT_COLUMNS, SentCounts, Sink, stream
from rig.emulator_settings import ReaderWait
from rig.errors import ConfigError
from rig.writers import CsvRecord
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import Motion, TrackerConfig, TrackerSamples, measure
from rig.sim.tracker_faults import ByteFaults, FaultPlan

MAX_PORT = 65535  # the largest TCP port
# The emulated device's clock starts here (s) when it starts sending, and runs `drift_ppm` fast.
DEVICE_EPOCH_S = 100.0


def quiet_tracker(rate_hz: float) -> TrackerConfig:
    """A tracker that measures exactly and sends at once: the emulator's unless told otherwise."""
    return TrackerConfig(rate_hz=rate_hz, position_noise_m=0.0, orientation_noise_deg=0.0, transport_delay_s=0.0, jitter_s=0.0)


@dataclass(frozen=True)
class EmulatorConfig:
    """One emulated tracker: where it sends (a pty link path, a TCP port, or an LSL name), what it
    measures (`tracker`: rate, noise, transport), for how long, in which format (the serial tracker's
    default profile unless told: what `rig record-tracker --tracker serial:PORT` reads), with which
    faults, and how long it waits for a reader."""

    transport: str
    address: str
    tracker: TrackerConfig = quiet_tracker(1000.0)
    duration_s: float = 10.0
    profile: str = DEFAULT_PROFILE
    trace: Path | None = None
    faults: FaultPlan = FaultPlan()
    seed: int = 0
    drift_ppm: float = 0.0
    log: Path | None = None
    idle_timeout_s: float = like(ReaderWait, "idle_timeout_s")

    def __post_init__(self) -> None:
        check(self, ConfigError)
        if self.transport == "lsl" and self.faults.damages_bytes:
            raise ConfigError("an LSL stream carries no bytes to damage: corrupt, drop and garbage are serial faults")


class LoopedTrace:
    """A recorded trace's truth played in a loop from its first sample, as a `Motion` at any time."""

    t_start, t_end = -np.inf, np.inf

    def __init__(self, path: Path, rate_hz: float) -> None:
        self._recorded = read_trace(path)
        self._first = float(self._recorded.truth_t[0])
        self._span = max(self._recorded.duration, 1.0 / rate_hz)

    def sensor_pose(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self._recorded.truth_at(self._first + np.mod(t, self._span))


def emulated_motion(config: EmulatorConfig) -> Motion:
    """The simulated pendulum from its release at time 0, or the trace in a loop."""
    if config.trace is not None:
        return LoopedTrace(config.trace, config.tracker.rate_hz)
    return Pendulum(PendulumConfig(), t_end=config.duration_s + 1.0)


def emulated_samples(config: EmulatorConfig) -> tuple[TrackerSamples, np.ndarray]:
    """What the emulated tracker measures over its duration, and the angular rate (rad/s, body frame,
    (N, 3)) at each sample: the true turn to the next sample's time, over that interval."""
    motion = emulated_motion(config)
    samples = measure(motion, config.tracker, 0.0, config.duration_s, config.seed, config.faults)
    step = 1.0 / config.tracker.rate_hz
    now = quaternion.normalise(motion.sensor_pose(samples.t_sensor)[1])
    after = quaternion.normalise(motion.sensor_pose(samples.t_sensor + step)[1])
    return samples, quaternion.to_rotation_vector(quaternion.multiply(quaternion.conjugate(now), after)) / step


def make_sink(config: EmulatorConfig) -> Sink:
    if config.transport == "lsl":
        return LslSink(config.address, config.tracker.rate_hz, source_id=f"rig-emulator-{config.address}")
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
    if not 0 <= port <= MAX_PORT:
        raise ConfigError(f"--tcp {port}: a TCP port is 0 to {MAX_PORT} (0: any free port)")
    return TcpSink(port, RecordEncoder(profile), faults)


def run_emulator(
    config: EmulatorConfig,
    sink: Sink,
    on_event: Callable[[str], None],
    on_start: Callable[[float], None] = lambda t: None,
    on_ready: Callable[[], None] = lambda: None,
) -> SentCounts:
    """Streams `config` through `sink` (from make_sink), logging every record's fate to config.log;
    `on_ready` is called once the samples are worked out, before it waits for a reader, and
    `on_start` is told the monotonic time (s) of the stream's time 0 once a reader is there. An LSL
    record is stamped with its sensor time on the LSL clock (the monotonic clock), a serial one with
    the device's own clock."""
    samples, rates = emulated_samples(config)
    on_ready()
    if config.transport == "lsl":
        device_clock: Callable[[float], float] = lambda t: t
    else:
        started = time.monotonic()
        device_clock = lambda t: DEVICE_EPOCH_S + (t - started) * (1.0 + config.drift_ppm * 1e-6)
    log = CsvRecord(config.log, SENT_COLUMNS, overwrite=True, flush_each_row=False) if config.log else None
    try:
        return stream(samples, rates, sink, config.tracker.rate_hz, config.faults.disconnect, device_clock, log, on_event, on_start,
                      config.idle_timeout_s)  # fmt: skip
    finally:
        if log is not None:
            log.close()
