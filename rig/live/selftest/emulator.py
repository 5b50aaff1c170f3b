"""The emulated tracker of the self-test and the live bench: the simulated pendulum streamed on an
LSL outlet by the rig's emulator (`rig.emulate`), from a process of its own, with the instant its
motion started on the rig clock (the camera twin draws the LED from it)."""

from __future__ import annotations

import math
import multiprocessing
import time
from typing import Any, Sequence

from rig.clock import MonotonicClock
from rig.emulate import EmulatorConfig, quiet_tracker, run_emulator
from rig.emulate.encode import Emission
from rig.emulate.sinks import LslSink
from rig.errors import RigError

TRACKER_HZ = 500.0
STOP_POLL_S = 0.1
STOP_TIMEOUT_S = 10.0
READY_TIMEOUT_S = 60.0


class _Stopped(Exception):
    """The run is over: the emulator stops sending."""


class _StoppableSink(LslSink):
    """The emulator's LSL outlet, which ends the sending loop once `stop` is set."""

    def __init__(self, name: str, rate_hz: float, stop: Any) -> None:
        super().__init__(name, rate_hz, source_id=name)
        self._stop = stop

    def wait_for_reader(self, stop_at: float) -> bool:
        while not self._stop.is_set() and time.monotonic() < stop_at:
            if super().wait_for_reader(min(stop_at, time.monotonic() + STOP_POLL_S)):
                return True
        return False

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]:
        if self._stop.is_set():
            raise _Stopped
        return super().send(emissions, rate_hz)


def _emulate(name: str, duration_s: float, rate_hz: float, origin_s: float, start: Any, ready: Any, stop: Any) -> None:
    """The emulator's process: `ready` once its outlet is up, then stream until the duration is over
    or `stop` is set; `start` gets the rig time of the motion's time 0."""
    sink = _StoppableSink(name, rate_hz, stop)
    ready.set()

    def started(t: float) -> None:
        start.value = t - origin_s

    try:
        run_emulator(EmulatorConfig("lsl", name, quiet_tracker(rate_hz), duration_s), sink, lambda message: None, started)
    except _Stopped:
        pass
    finally:
        sink.close()


class EmulatedPendulum:
    """The emulated LSL tracker `name` streaming the simulated pendulum for `duration_s` once a reader
    connects, from a process of its own (a thread of the rig's would starve while the rig renders);
    `start` is when the motion's time 0 was, on `clock` (None before it starts)."""

    def __init__(self, name: str, duration_s: float, clock: MonotonicClock, rate_hz: float = TRACKER_HZ) -> None:
        context = multiprocessing.get_context("spawn")
        self._start = context.Value("d", math.nan)
        self._stop = context.Event()
        ready = context.Event()
        self._process = context.Process(
            target=_emulate, args=(name, duration_s, rate_hz, clock.origin_ns / 1e9, self._start, ready, self._stop),
            name="emulated tracker", daemon=True,
        )  # fmt: skip
        self._process.start()
        if not ready.wait(READY_TIMEOUT_S):
            self.close()
            raise RigError(f"the emulated tracker did not start within {READY_TIMEOUT_S:g} s")

    @property
    def start(self) -> float | None:
        value = self._start.value
        return None if math.isnan(value) else value

    def close(self) -> None:
        self._stop.set()
        self._process.join(STOP_TIMEOUT_S)
        if self._process.is_alive():
            self._process.terminate()
            self._process.join()
