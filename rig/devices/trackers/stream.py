"""One real tracker source: a link read by its own thread, samples handed over without blocking.

`TrackerStream` is the `TrackerSource` (rig.devices.protocols) of every real tracker. Its link
(serial, HID, LSL) receives what the device sends on a reader thread, which stamps each chunk with
its arrival time and queues it: that is all the thread does per wake-up, because at 1000 records a
second the wake-ups are most of the cost, and code run once per wake-up runs cold, several times
slower than the same code run over a batch. Where the link has a compiled reader
(`Link.native_reader`: a serial port with a file descriptor, or an LSL inlet, on the system's
monotonic clock), that thread is in C and never wakes the interpreter; the stream's own thread only
supervises it, asleep in C until it ends, and reopens the link when it does. Elsewhere (a port
without a descriptor, HID, a test's clock) the stream's thread is the reader, in Python, calling
`Link.receive`. The consumer's `poll()` (the session's render loop, or `rig record-tracker`), which
never blocks, or `wait(timeout)`, takes every queued chunk and decodes them together into columns
(`Readings`), checked and counted a batch at a time, then maps the device times of all it took onto
the rig clock in one call. It runs cold, every 20 ms or so, where each distinct function it calls
costs several microseconds to bring back into the caches, more than a record's work: so each step is
one loop over the batch (or one call that does the batch in C), not a chain of small batch
operations, and no Python call or object per record beyond the record itself. A record is available
to a predictor from its arrival time, when the reader queued the chunk that completed it. A lost
link is logged, leaves a gap, and is reopened until the stream is closed; everything that happened
is in `report()`. One thread consumes a stream.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections import deque
from dataclasses import dataclass
from functools import partial
from itertools import repeat
from operator import sub
from typing import Any, Callable, NamedTuple

from predictors import PoseSample
from rig.clock import Clock
from rig.devices.protocols import Fault
from rig.devices.trackers.clock_mapping import ClockMapping
from rig.devices.trackers.counters import LatencyHistogram, SequenceCheck, TrackerCounters
from rig.devices.trackers.link import Link, LinkLost, NativeReader
from rig.devices.trackers.readings import keep_possible
from rig.errors import RigError

log = logging.getLogger("rig.trackers")

RECONNECT_FIRST_WAIT_S = 0.02
RECONNECT_LONGEST_WAIT_S = 0.5
# Impossible records whose reason is logged; the rest are only counted.
LOGGED_REJECTIONS = 5
# A silence this long between samples is logged as a gap (a stall, a sender that went away).
GAP_S = 0.25
# How often the supervisor of a compiled reader lets the link do its upkeep (`Link.upkeep`).
UPKEEP_INTERVAL_S = 0.25


_RESTORED = object()
"""Queued after the chunks of a lost link, before those of the reopened one."""
_CLOSED = object()
"""Queued after the last chunk, once the stream is closed: what the decoder holds is incomplete."""


class TrackerRecord(NamedTuple):
    """A checked record: its sensor and arrival times on the rig clock (s), position (m) and unit
    orientation (w, x, y, z), and what the device said beside them: its own time (s), counter and
    angular rate (rad/s). Plain numbers: a recording writes them as they are, and only a predictor
    that asks for the `sample` pays for building one."""

    t_sensor: float
    t_arrival: float
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    device_time: float | None
    seq: int | None
    angular_rate: tuple[float, float, float] | None

    @classmethod
    def of_sample(cls, sample: PoseSample) -> TrackerRecord:
        """The record of a source that says nothing beside the pose."""
        return cls(sample.t_sensor, sample.t_arrival, tuple(sample.position.tolist()), tuple(sample.orientation.tolist()), None, None, None)

    @property
    def sample(self) -> PoseSample:
        return PoseSample(self.t_sensor, self.t_arrival, self.position, self.orientation)

    def sample_row(self) -> tuple[float, ...]:
        """The sample's values in the trace format's order (`predictors.SAMPLE_COLUMNS`)."""
        return (self.t_sensor, self.t_arrival, *self.position, *self.orientation)


_record = partial(tuple.__new__, TrackerRecord)
"""A TrackerRecord of the tuple of its fields, as its `_make` makes one, without a Python call."""
_NONE = repeat(None)
"""The column of a field the device does not send."""


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
        self.decode_cpu_s = 0.0
        """CPU time the consumer has spent decoding, checking and mapping records."""
        self._unit_tolerance = unit_tolerance
        self._sequence = SequenceCheck(self.counters, sequence_bits)
        self._describe = describe
        self._clock: Clock | None = None
        self._chunks: deque[tuple[Any, float] | NativeReader | object] = deque()
        """In order: (payload, arrival time) as the Python reader received it, a compiled reader that
        has ended (what it read last is still in it), and the markers below."""
        self._native: NativeReader | None = None
        """The link's compiled reader, where it has one (the latest, after a reconnection)."""
        self._ready = threading.Condition()
        self._waiting = False
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
        self._native = self.link.native_reader(clock)
        self._thread = threading.Thread(target=self._run, name=f"tracker {self.name}", daemon=True)
        self._thread.start()

    def poll(self) -> list[PoseSample]:
        return [record.sample for record in self.poll_records()]

    def wait(self, timeout_s: float) -> list[PoseSample]:
        return [record.sample for record in self.wait_records(timeout_s)]

    def poll_records(self) -> list[TrackerRecord]:
        """Every record received since the last call, in arrival order; never blocks."""
        records = self.take_queued()
        if not records:
            self._raise_failure()
        return records

    def take_queued(self) -> list[TrackerRecord]:
        """Every record received, whatever became of the reader (for the end of a run)."""
        started = time.thread_time()
        # Looked at before the queue: a reader that replaced it comes after its marker in the queue.
        native = self._native
        queue = self._chunks
        records: list[TrackerRecord] = []
        chunks: list[Any] = []
        arrivals: list[float] = []
        while queue:
            entry = queue.popleft()
            if type(entry) is tuple:
                chunks.append(entry[0])
                arrivals.append(entry[1])
            elif entry is _RESTORED or entry is _CLOSED:
                self._decode(chunks, arrivals, records)
                chunks, arrivals = [], []
                if entry is _RESTORED:
                    self._restart()
                else:
                    self.link.restart()
                    self._count_corrupt()
            else:
                taken, times = entry.take()  # type: ignore[union-attr]
                chunks += taken
                arrivals += times
        if native is not None:
            taken, times = native.take()
            chunks += taken
            arrivals += times
        self._decode(chunks, arrivals, records)
        self.decode_cpu_s += time.thread_time() - started
        return records

    def wait_records(self, timeout_s: float) -> list[TrackerRecord]:
        """As poll_records, after waiting up to `timeout_s` for something to arrive: in the compiled
        reader while it reads, else until the stream's thread queues something."""
        native = self._native
        reading = native is not None and native.outcome is None
        with self._ready:
            self._waiting = True
            idle = not self._chunks and self._failure is None
            if idle and not reading:
                self._ready.wait(timeout_s)
            self._waiting = False
        if idle and reading:
            native.wait(timeout_s)  # type: ignore[union-attr]
        return self.poll_records()

    def close(self) -> None:
        """Stops the reader and closes the link; safe to call more than once."""
        with self._ready:
            self._stop.set()
            native = self._native
        if native is not None:
            native.stop()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join()
            self._chunks.append(_CLOSED)
        self.link.close()

    def fault(self) -> Fault | None:
        """The link's loss, while it has not been restored."""
        change = next((event for event in reversed(self.events) if event.what in ("lost", "restored")), None)
        return Fault(change.t, f"tracker {self.name} was lost ({change.detail})") if change and change.what == "lost" else None

    def report(self) -> dict[str, Any]:
        """Counters, latency (where knowable), clock mapping and link events, for the end of a run."""
        self._count_corrupt()
        return {
            "tracker": self.name,
            "link": self.link.description,
            **self._describe(),
            "counters": self.counters.as_dict(),
            "reader_cpu_us_per_sample": self.reader_cpu_s / max(self.counters.received, 1) * 1e6,
            "reading_cpu_us_per_sample": (self.reader_cpu_s + self.decode_cpu_s) / max(self.counters.received, 1) * 1e6,
            "latency": self.latency.summary() if self.mapping.latency_known else None,
            "clock_mapping": self.mapping.describe(),
            "events": [{"t": e.t, "what": e.what, "detail": e.detail} for e in sorted(self.events, key=lambda e: e.t)],
        }

    def _raise_failure(self) -> None:
        if self._failure is not None:
            raise RigError(f"tracker {self.name} stopped reading: {type(self._failure).__name__}: {self._failure}")

    def _count_corrupt(self) -> None:
        """Adds the link's new damaged records to the counters; the record counter's check learns of
        each where it was in the stream, from the reading after it (`Readings.discarded`)."""
        new = self.link.corrupt - self._corrupt_seen
        if new:
            self._corrupt_seen = self.link.corrupt
            self.counters.corrupt += new

    def _run(self) -> None:
        """The stream's thread: reads the link, or waits for its compiled reader to end, and
        reopens the link whenever it is lost, until the stream is closed."""
        started = time.thread_time()
        try:
            while (lost := self._read() if self._native is None else self._supervise(self._native)) is not None:
                self._lost(lost)
                if not self._reopen():
                    return
        except BaseException as error:  # noqa: BLE001 - handed to the consumer's thread, never lost
            self._failure = error
            self._wake()
        finally:
            self.reader_cpu_s += time.thread_time() - started

    def _read(self) -> str | None:
        """Receives, stamps and queues until the link is lost (what happened) or the stream is closed
        (None); run once per wake-up, so it touches as little as it can (bound methods, a plain
        tuple per chunk)."""
        clock = self._clock
        receive, now, queue, stopped = self.link.receive, clock.now, self._chunks.append, self._stop.is_set  # type: ignore[union-attr]
        while not stopped():
            try:
                payload = receive(clock)
            except LinkLost as lost:
                return str(lost)
            if payload is not None:
                queue((payload, now()))
                if self._waiting:
                    self._wake()
        return None

    def _supervise(self, native: NativeReader) -> str | None:
        """Sleeps (in C, the GIL released) until the compiled reader ends, waking for the link's
        upkeep, and queues the reader for the consumer to take what it read last; what happened to
        the link, or None if the stream was closed."""
        while not native.wait_ended(UPKEEP_INTERVAL_S):
            self.link.upkeep(self._clock)  # type: ignore[arg-type]
        self.reader_cpu_s += native.cpu_s
        self._chunks.append(native)
        self._wake()
        if native.outcome == "stopped" or self._stop.is_set():
            return None
        if native.outcome == "error":
            code = native.errno
            return str(OSError(code, os.strerror(code))) if code > 0 else f"the stream failed (liblsl error {code})"
        return "the device closed the link (end of file)"

    def _decode(self, chunks: list[Any], arrivals: list[float], records: list[TrackerRecord]) -> None:
        """Decodes, checks and counts the readings of chunks taken together, in order, lets the clock
        mapping learn from the possible ones and then maps them in one call (so they keep their order
        in sensor time), and adds their records to `records`."""
        if not chunks:
            return
        readings = self.link.decode(chunks, arrivals)
        self._count_corrupt()
        problems = keep_possible(readings, self._unit_tolerance)
        if problems:
            self._reject(problems)
        self._sequence.accept(readings)
        if not readings:
            return
        mapping, arrivals, device_times = self.mapping, readings.arrivals, readings.device_times
        mapping.observe_many(device_times, arrivals)
        self._note_gaps(arrivals)
        self.counters.received += len(arrivals)
        sensor_times = mapping.sensor_times(device_times, arrivals)
        if mapping.latency_known:
            self.latency.add_many(map(sub, arrivals, sensor_times))
        fields = (readings.positions, readings.orientations, device_times or _NONE, readings.seqs or _NONE, readings.rates or _NONE)
        records.extend(map(_record, zip(sensor_times, arrivals, *fields)))

    def _reject(self, problems: list[str]) -> None:
        counters = self.counters
        for problem in problems:
            counters.rejected += 1
            if counters.rejected <= LOGGED_REJECTIONS:
                log.warning("tracker %s: impossible record discarded: %s", self.name, problem)

    def _note_gaps(self, arrivals: list[float]) -> None:
        """A gap event for each silence longer than GAP_S before a sample."""
        last = self._last_arrival
        for t_arrival in arrivals:
            if last is not None and t_arrival - last > GAP_S:
                self._event("gap", f"no samples for {t_arrival - last:.3f} s", t_arrival)
            last = t_arrival
        self._last_arrival = last

    def _wake(self) -> None:
        """Wakes a consumer in `wait_records`: the reader appends without the lock (a deque's append
        is atomic), and a consumer sets `_waiting` under it before it looks at the chunks, so a
        chunk that comes after its look finds the flag set."""
        with self._ready:
            self._ready.notify_all()

    def _restart(self) -> None:
        """The chunks of a reopened link follow: a partial record is forgotten (and counted), a
        counter or device clock may start again."""
        self.link.restart()
        self._count_corrupt()
        self._sequence.link_restored()
        self.mapping.restart()

    def _event(self, what: str, detail: str, t: float | None = None) -> None:
        event = LinkEvent(self._clock.now() if t is None else t, what, detail)
        self.events.append(event)
        log.warning("tracker %s: link %s at %.3f s: %s", self.name, what, event.t, detail)

    def _lost(self, detail: str) -> None:
        self.link.close()
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
            native = self.link.native_reader(self._clock)
            self.counters.reconnects += 1
            self._chunks.append(_RESTORED)
            with self._ready:
                # Published after the marker: a consumer takes from it once it has taken the marker.
                self._native = native
                closed = self._stop.is_set()
                self._ready.notify_all()
            if closed and native is not None:
                native.stop()  # close() stopped the reader it saw, the one before
            self._event("restored", self.link.description)
            return True
        return False
