"""One real tracker source: a link read by its own thread, samples handed over without blocking.

`TrackerStream` is the `TrackerSource` (rig.devices.protocols) of every real tracker. Its link
(serial, HID, LSL) turns what the device sends into readings; the stream's reader thread checks
each one, maps its device time onto the rig clock, counts what was wrong, and queues the sample.
The session (or `rig record-tracker`) takes samples with `poll()`, which never blocks, or waits for
the next with `wait(timeout)`. A lost link is logged, leaves a gap, and is reopened until the
stream is closed; everything that happened is in `report()`.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any, Callable, Protocol

from predictors import PoseSample
from rig.clock import Clock
from rig.devices.trackers.clock_mapping import ClockMapping
from rig.devices.trackers.counters import LatencyHistogram, SequenceCheck, TrackerCounters
from rig.devices.trackers.readings import Reading, check_reading
from rig.errors import RigError

log = logging.getLogger("rig.trackers")

RECONNECT_FIRST_WAIT_S = 0.02
RECONNECT_LONGEST_WAIT_S = 0.5
# Impossible records whose reason is logged; the rest are only counted.
LOGGED_REJECTIONS = 5
# A silence this long between samples is logged as a gap (a stall, a sender that went away).
GAP_S = 0.25


class LinkLost(Exception):
    """The device went away while reading (unplugged, the socket closed, the stream ended)."""


class Link(Protocol):
    """What a stream reads: a device's transport and its decoder. `read` waits briefly (tens of ms)
    so the reader notices close; it returns the readings completed, stamped with `clock`."""

    description: str
    corrupt: int

    def open(self, clock: Clock) -> None:
        """Opens the device, its times to go on `clock`; RigError saying what to do if it cannot."""

    def read(self, clock: Clock) -> list[Reading]:
        """Raises LinkLost when the device went away."""

    def close(self) -> None: ...


@dataclass(frozen=True)
class TrackerRecord:
    """A sample and what the device said beside it: its own time (s), counter, angular rate (rad/s)."""

    sample: PoseSample
    device_time: float | None
    seq: int | None
    angular_rate: tuple[float, float, float] | None


@dataclass(frozen=True)
class LinkEvent:
    t: float
    what: str
    detail: str


class TrackerStream:
    """A `TrackerSource` reading `link` on a thread; `mapping` gives sensor times, `sequence_bits`
    is the width of the device's record counter (None: it has none)."""

    def __init__(
        self,
        name: str,
        link: Link,
        mapping: ClockMapping,
        *,
        unit_tolerance: float,
        sequence_bits: int | None,
        describe: Callable[[], dict[str, Any]] = dict,
    ) -> None:
        self.name = name
        self.link = link
        self.mapping = mapping
        self.counters = TrackerCounters()
        self.latency = LatencyHistogram()
        self.events: list[LinkEvent] = []
        self.reader_cpu_s = 0.0
        """CPU time the reader thread has used, once it has ended (after close)."""
        self._unit_tolerance = unit_tolerance
        self._sequence = SequenceCheck(self.counters, sequence_bits)
        self._describe = describe
        self._clock: Clock | None = None
        self._queue: deque[TrackerRecord] = deque()
        self._ready = threading.Condition()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._failure: BaseException | None = None
        self._corrupt_seen = 0
        self._last_arrival: float | None = None

    def connect(self, clock: Clock) -> None:
        """Opens the link (RigError if it cannot) and starts reading."""
        if self._thread is not None:
            raise RigError(f"tracker {self.name} is already connected")
        self._clock = clock
        self.link.open(clock)
        self._stop.clear()
        self._thread = threading.Thread(target=self._read_loop, name=f"tracker {self.name}", daemon=True)
        self._thread.start()

    def poll(self) -> list[PoseSample]:
        return [record.sample for record in self.poll_records()]

    def wait(self, timeout_s: float) -> list[PoseSample]:
        return [record.sample for record in self.wait_records(timeout_s)]

    def poll_records(self) -> list[TrackerRecord]:
        """Every record queued since the last call, in arrival order; never blocks."""
        records = self.take_queued()
        if not records:
            self._raise_failure()
        return records

    def take_queued(self) -> list[TrackerRecord]:
        """Every record queued, whatever became of the reader (for the end of a run)."""
        with self._ready:
            records = list(self._queue)
            self._queue.clear()
        return records

    def wait_records(self, timeout_s: float) -> list[TrackerRecord]:
        """As poll_records, after waiting up to `timeout_s` for the first."""
        with self._ready:
            if not self._queue and self._failure is None:
                self._ready.wait(timeout_s)
        return self.poll_records()

    def close(self) -> None:
        """Stops the reader and closes the link; safe to call more than once."""
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join()
        self.link.close()

    def report(self) -> dict[str, Any]:
        """Counters, latency (where knowable), clock mapping and link events, for the end of a run."""
        self._count_corrupt()
        return {
            "tracker": self.name,
            "link": self.link.description,
            **self._describe(),
            "counters": self.counters.as_dict(),
            "reader_cpu_us_per_sample": self.reader_cpu_s / max(self.counters.received, 1) * 1e6,
            "latency": self.latency.summary() if self.mapping.latency_known else None,
            "clock_mapping": self.mapping.describe(),
            "events": [{"t": e.t, "what": e.what, "detail": e.detail} for e in self.events],
        }

    def _raise_failure(self) -> None:
        if self._failure is not None:
            raise RigError(f"tracker {self.name} stopped reading: {type(self._failure).__name__}: {self._failure}")

    def _count_corrupt(self) -> None:
        new = self.link.corrupt - self._corrupt_seen
        if new:
            self._corrupt_seen = self.link.corrupt
            self.counters.corrupt += new
            self._sequence.discarded(new)

    def _read_loop(self) -> None:
        started = time.thread_time()
        try:
            while not self._stop.is_set():
                try:
                    readings = self.link.read(self._clock)
                except LinkLost as lost:
                    self._lost(str(lost))
                    if not self._reopen():
                        return
                    continue
                self._count_corrupt()
                if readings:
                    self._accept(readings)
        except BaseException as error:  # noqa: BLE001 - handed to the session's thread, never lost
            self._failure = error
            with self._ready:
                self._ready.notify_all()
        finally:
            self.reader_cpu_s += time.thread_time() - started

    def _accept(self, readings: list[Reading]) -> None:
        """Checks, counts and queues the readings of one read; the clock mapping learns from all of
        them before it maps any, so records read together keep their order in sensor time."""
        counters, mapping = self.counters, self.mapping
        possible = []
        for reading in readings:
            problem = check_reading(reading, self._unit_tolerance)
            if problem is not None:
                counters.rejected += 1
                self._sequence.discarded(1)
                if counters.rejected <= LOGGED_REJECTIONS:
                    log.warning("tracker %s: impossible record discarded: %s", self.name, problem)
                continue
            self._sequence.accept(reading.seq, reading.device_time)
            mapping.observe(reading.device_time, reading.t_arrival)
            possible.append(reading)
        records = []
        for reading in possible:
            t_sensor = mapping.sensor_time(reading.device_time, reading.t_arrival)
            if mapping.latency_known:
                self.latency.add(reading.t_arrival - t_sensor)
            sample = PoseSample(t_sensor, reading.t_arrival, reading.position, reading.orientation)
            records.append(TrackerRecord(sample, reading.device_time, reading.seq, reading.angular_rate))
        counters.received += len(records)
        if records:
            first = records[0].sample.t_arrival
            if self._last_arrival is not None and first - self._last_arrival > GAP_S:
                self._event("gap", f"no samples for {first - self._last_arrival:.3f} s")
            self._last_arrival = records[-1].sample.t_arrival
            with self._ready:
                self._queue.extend(records)
                self._ready.notify_all()

    def _event(self, what: str, detail: str) -> None:
        event = LinkEvent(self._clock.now(), what, detail)
        self.events.append(event)
        log.warning("tracker %s: link %s at %.3f s: %s", self.name, what, event.t, detail)

    def _lost(self, detail: str) -> None:
        self.link.close()
        self._count_corrupt()
        self._event("lost", f"{detail}; reconnecting")

    def _reopen(self) -> bool:
        wait = RECONNECT_FIRST_WAIT_S
        while not self._stop.is_set():
            try:
                self.link.open(self._clock)
            except RigError:
                self._stop.wait(wait)
                wait = min(2 * wait, RECONNECT_LONGEST_WAIT_S)
                continue
            self.counters.reconnects += 1
            self._sequence.link_restored()
            self.mapping.restart()
            self._event("restored", self.link.description)
            return True
        return False
