"""One real tracker source: a transport's reader thread and a profile's decoder, samples handed
over without blocking.

`TrackerStream` is the `TrackerSource` (rig.devices.protocols) of every real tracker. Its transport
(serial, HID, LSL: `rig.devices.trackers.transport`) reads on a thread of its own that only stamps
each chunk with its arrival and queues it: that is all that runs per wake-up, because at 1000
records a second the wake-ups are most of the cost, and code run once per wake-up runs cold, several
times slower than the same code run over a batch. The stream's own thread only supervises the
reader, asleep until it ends (waking for the transport's upkeep), and reopens the transport when it
does. The consumer's `poll()` (the session's render loop, or `rig record-tracker`), which never
blocks, or `wait(timeout)`, takes every queued chunk and has the decoder turn them together into
columns (`Readings`), checked and counted a batch at a time, then maps the device times of all it
took onto the rig clock in one call. It runs cold, every 20 ms or so, where each distinct function it
calls costs several microseconds to bring back into the caches, more than a record's work: so each
step is one loop over the batch (or one call that does the batch in C), not a chain of small batch
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
from dataclasses import asdict, dataclass
from functools import partial
from itertools import repeat
from operator import sub
from typing import Any, Callable, NamedTuple, Protocol, runtime_checkable

from predictors import PoseSample
from rig.clock import Clock
from rig.devices.protocols import Fault
from rig.devices.trackers.clock_mapping import ClockMapping, mapping_for
from rig.devices.trackers.counters import LatencyHistogram, SequenceCheck, TrackerCounters
from rig.devices.trackers.decoders import Decoder
from rig.devices.trackers.profile import Profile
from rig.devices.trackers.readings import keep_possible
from rig.devices.trackers.transport import Reader, Transport, monotonic_origin_ns
from rig.errors import RigError

log = logging.getLogger("rig.trackers")

RECONNECT_FIRST_WAIT_S = 0.02
RECONNECT_LONGEST_WAIT_S = 0.5
# Impossible records whose reason is logged; the rest are only counted.
LOGGED_REJECTIONS = 5
# A silence this long between samples is logged as a gap (a stall, a sender that went away).
GAP_S = 0.25
# How often the supervisor lets the transport do its upkeep (`Transport.upkeep`).
UPKEEP_INTERVAL_S = 0.25


_RESTORED = object()
"""Queued after the reader of a lost link, before the reopened one's chunks."""
_CLOSED = object()
"""Queued after the last reader, once the stream is closed: what the decoder holds is incomplete."""


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


@runtime_checkable
class RecordSource(Protocol):
    """A tracker source whose records hold what the device said beside the pose (`TrackerRecord`):
    a recording writes them whole, and `rig check` reads the device's own clock from them. A
    `TrackerStream` is one; any other source is recorded from its samples alone."""

    def poll_records(self) -> list[TrackerRecord]: ...

    def wait_records(self, timeout_s: float) -> list[TrackerRecord]: ...

    def take_queued(self) -> list[TrackerRecord]: ...


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
    """A `TrackerSource` reading `transport` through `decoder`; `mapping` gives sensor times,
    `sequence_bits` is the width of the device's record counter (None: it has none)."""

    def __init__(
        self,
        name: str,
        transport: Transport,
        decoder: Decoder,
        mapping: ClockMapping,
        *,
        unit_tolerance: float,
        sequence_bits: int | None,
        describe: Callable[[], dict[str, Any]] = dict,
    ) -> None:
        self.name = name
        self.transport = transport
        self.decoder = decoder
        self.mapping = mapping
        self.counters = TrackerCounters()
        self.latency = LatencyHistogram()
        self.events: list[LinkEvent] = []
        self.reader_cpu_s = 0.0
        """CPU time the reader and supervising threads have used, once they have ended (after close)."""
        self.decode_cpu_s = 0.0
        """CPU time the consumer has spent decoding, checking and mapping records."""
        self._unit_tolerance = unit_tolerance
        self._sequence = SequenceCheck(self.counters, sequence_bits)
        self._describe = describe
        self._clock: Clock | None = None
        self._origin_ns = 0
        """The system's monotonic time at the clock's zero, which every reader stamps from."""
        self._ended: deque[Reader | object] = deque()
        """In order: readers that have ended (what they read last is still in them), and the markers."""
        self._reader: Reader | None = None
        """The transport's reader (the latest, after a reconnection)."""
        self._ready = threading.Condition()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._failure: BaseException | None = None
        self._corrupt_seen = 0
        self._last_arrival: float | None = None

    def connect(self, clock: Clock) -> None:
        """Opens the transport (RigError if it cannot) and starts reading."""
        if self._thread is not None:
            raise RigError(f"tracker {self.name} is already connected")
        self._clock = clock
        self._origin_ns = monotonic_origin_ns(clock)
        self.transport.open(self._origin_ns)
        self._stop.clear()
        self._reader = self.transport.reader()
        self._thread = threading.Thread(target=self._run, name=f"tracker {self.name}", daemon=True)
        self._thread.start()

    def poll(self) -> list[PoseSample]:
        return [record.sample for record in self.poll_records()]

    def wait(self, timeout_s: float) -> list[PoseSample]:
        return [record.sample for record in self.wait_records(timeout_s)]

    def poll_records(self) -> list[TrackerRecord]:
        """Every record received since the last call, in arrival order; never blocks."""
        records = self.take_queued()
        if not records and self._failure is not None:
            raise RigError(f"tracker {self.name} stopped reading: {type(self._failure).__name__}: {self._failure}")
        return records

    def take_queued(self) -> list[TrackerRecord]:
        """Every record received, whatever became of the reader (for the end of a run)."""
        started = time.thread_time()
        # Looked at before the queue: a reader that replaced it comes after its marker in the queue.
        current = self._reader
        queue = self._ended
        records: list[TrackerRecord] = []
        chunks: list[Any] = []
        arrivals: list[float] = []
        while queue:
            entry = queue.popleft()
            if entry is _RESTORED or entry is _CLOSED:
                self._decode(chunks, arrivals, records)
                chunks, arrivals = [], []
                self._restart(restored=entry is _RESTORED)
            else:
                taken, times = entry.take()  # type: ignore[union-attr]
                chunks += taken
                arrivals += times
        if current is not None:
            taken, times = current.take()
            chunks += taken
            arrivals += times
        self._decode(chunks, arrivals, records)
        self.decode_cpu_s += time.thread_time() - started
        return records

    def wait_records(self, timeout_s: float) -> list[TrackerRecord]:
        """As poll_records, after waiting up to `timeout_s` for something to arrive: in the reader
        while it reads, else (between a lost link and its reopening) for the next reader."""
        reader = self._reader
        if reader is not None and reader.outcome is None:
            reader.wait(timeout_s)
        else:
            with self._ready:
                if not self._ended and self._failure is None and self._reader is reader:
                    self._ready.wait(timeout_s)
        return self.poll_records()

    def close(self) -> None:
        """Stops the reader and closes the transport; safe to call more than once."""
        with self._ready:
            self._stop.set()
            reader = self._reader
        if reader is not None:
            reader.stop()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join()
            self._ended.append(_CLOSED)
        self.transport.close()

    def fault(self) -> Fault | None:
        """The link's loss, while it has not been restored."""
        change = next((event for event in reversed(self.events) if event.what in ("lost", "restored")), None)
        return Fault(change.t, f"tracker {self.name} was lost ({change.detail})") if change and change.what == "lost" else None

    def report(self) -> dict[str, Any]:
        """Counters, latency (where knowable), clock mapping and link events, for the end of a run."""
        self._count_corrupt()
        return {
            "tracker": self.name,
            "link": self.transport.description,
            **self._describe(),
            "counters": asdict(self.counters),
            "reader_cpu_us_per_sample": self.reader_cpu_s / max(self.counters.received, 1) * 1e6,
            "reading_cpu_us_per_sample": (self.reader_cpu_s + self.decode_cpu_s) / max(self.counters.received, 1) * 1e6,
            "latency": self.latency.summary() if self.mapping.latency_known else None,
            "clock_mapping": self.mapping.describe(),
            "events": [{"t": e.t, "what": e.what, "detail": e.detail} for e in sorted(self.events, key=lambda e: e.t)],
        }

    def _count_corrupt(self) -> None:
        """Adds the decoder's new damaged records to the counters; the record counter's check learns of
        each where it was in the stream, from the reading after it (`Readings.discarded`)."""
        new = self.decoder.corrupt - self._corrupt_seen
        if new:
            self._corrupt_seen = self.decoder.corrupt
            self.counters.corrupt += new

    def _run(self) -> None:
        """The stream's thread: waits for the reader to end, and reopens the transport whenever the
        link is lost, until the stream is closed."""
        started = time.thread_time()
        try:
            while (lost := self._supervise(self._reader)) is not None:  # type: ignore[arg-type]
                self.transport.close()
                self._event("lost", f"{lost}; reconnecting")
                if not self._reopen():
                    return
        except BaseException as error:  # noqa: BLE001 - handed to the consumer's thread, never lost
            self._failure = error
            with self._ready:
                self._ready.notify_all()
        finally:
            self.reader_cpu_s += time.thread_time() - started

    def _supervise(self, reader: Reader) -> str | None:
        """Sleeps (in the reader's wait, the GIL released) until the reader ends, waking for the
        transport's upkeep, and queues it for the consumer to take what it read last; what happened
        to the link, or None if the stream was closed."""
        while not reader.wait_ended(UPKEEP_INTERVAL_S):
            self.transport.upkeep()
        self.reader_cpu_s += reader.cpu_s
        with self._ready:
            self._ended.append(reader)
            self._ready.notify_all()
        if reader.outcome == "stopped" or self._stop.is_set():
            return None
        if reader.outcome == "error":
            code = reader.errno
            return str(OSError(code, os.strerror(code))) if code > 0 else f"the stream failed (liblsl error {code})"
        return "the device closed the link (end of file)"

    def _decode(self, chunks: list[Any], arrivals: list[float], records: list[TrackerRecord]) -> None:
        """Decodes, checks and counts the readings of chunks taken together, in order, lets the clock
        mapping learn from the possible ones and then maps them in one call (so they keep their order
        in sensor time), and adds their records to `records`."""
        if not chunks:
            return
        readings = self.decoder.feed_chunks(chunks, arrivals)
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

    def _restart(self, restored: bool) -> None:
        """A partial record is forgotten (and counted); after a reconnection (`restored`) the
        chunks of a reopened link follow, whose counter or device clock may start again."""
        self.decoder.reset()
        self._count_corrupt()
        if restored:
            self._sequence.link_restored()
            self.mapping.restart()

    def _event(self, what: str, detail: str, t: float | None = None) -> None:
        event = LinkEvent(self._clock.now() if t is None else t, what, detail)
        self.events.append(event)
        log.warning("tracker %s: link %s at %.3f s: %s", self.name, what, event.t, detail)

    def _reopen(self) -> bool:
        wait = RECONNECT_FIRST_WAIT_S
        while not self._stop.is_set():
            try:
                self.transport.open(self._origin_ns)
            except RigError:
                self._stop.wait(wait)
                wait = min(2 * wait, RECONNECT_LONGEST_WAIT_S)
                continue
            reader = self.transport.reader()
            self.counters.reconnects += 1
            with self._ready:
                # Published after the marker: a consumer takes from it once it has taken the marker.
                self._ended.append(_RESTORED)
                self._reader = reader
                closed = self._stop.is_set()
                self._ready.notify_all()
            if closed:
                reader.stop()  # close() stopped the reader it saw, the one before
            self._event("restored", self.transport.description)
            return True
        return False


def profile_stream(name: str, transport: Transport, decoder: Decoder, profile: Profile) -> TrackerStream:
    """A stream of the records `profile` lays out: its clock mapping, checks and record counter."""
    return TrackerStream(
        name,
        transport,
        decoder,
        mapping_for(profile),
        unit_tolerance=profile.unit_tolerance,
        sequence_bits=profile.sequence_bits,
        describe=lambda: {"profile": profile.describe()},
    )
