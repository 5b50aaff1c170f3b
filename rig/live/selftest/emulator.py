"""The emulated tracker of the self-test and the live bench: the simulated pendulum streamed on an
LSL outlet by the rig's emulator (`rig.emulate`), on a thread of the rig's process, with the instant
its motion started on the rig clock (the camera twin draws the LED from it)."""

from __future__ import annotations

import threading
import time
from typing import Sequence

from rig.clock import MonotonicClock
from rig.emulate.encode import Emission
from rig.emulate.faults import FaultPlan
from rig.emulate.motion import Motion
from rig.emulate.sinks import LslSink
from rig.emulate.streamer import stream

TRACKER_HZ = 500.0
STOP_POLL_S = 0.1


class _Stopped(Exception):
    """The run is over: the emulator stops sending."""


class _StoppableSink(LslSink):
    """The emulator's LSL outlet, which ends the sending loop once the run is over."""

    stopped = False

    def wait_for_reader(self, stop_at: float) -> bool:
        while not self.stopped and time.monotonic() < stop_at:
            if super().wait_for_reader(min(stop_at, time.monotonic() + STOP_POLL_S)):
                return True
        return False

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]:
        if self.stopped:
            raise _Stopped
        return super().send(emissions, rate_hz)


class EmulatedPendulum:
    """The emulated LSL tracker `name` streaming the simulated pendulum on a thread for `duration_s`
    once a reader connects; `start` is when the motion's time 0 was, on `clock`."""

    def __init__(self, name: str, duration_s: float, clock: MonotonicClock, rate_hz: float = TRACKER_HZ) -> None:
        self.start: float | None = None
        self.events: list[str] = []
        self._origin = clock.origin_ns / 1e9
        self._sink = _StoppableSink(name, rate_hz, source_id=name)
        self._motion = Motion(rate_hz, duration_s)
        self._thread = threading.Thread(target=self._run, args=(duration_s,), name="emulated tracker", daemon=True)
        self._thread.start()

    def _device_clock(self, t: float) -> float:
        if self.start is None:
            self.start = t - self._origin
        return t

    def _run(self, duration_s: float) -> None:
        try:
            stream(self._motion, self._sink, duration_s, FaultPlan(), self._device_clock, None, self.events.append)
        except _Stopped:
            pass

    def close(self) -> None:
        self._sink.stopped = True
        self._thread.join()
        self._sink.close()
