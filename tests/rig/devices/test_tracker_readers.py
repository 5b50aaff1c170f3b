"""The tracker readers: a port with a file descriptor is read by a compiled thread of its own
(`_readers.FdReader`), anything else by a `ThreadReader` in Python with the same contract. Each
queues every chunk in order, stamped between the clock readings around its writing, and ends as the
link does; a serial tracker reads through the compiled thread whatever its clock, its stamps on
that clock's time line."""

from __future__ import annotations

import errno
import os
import pty
import select
import socket
import threading
import time
import tty
from typing import Callable, Iterator

import pytest

from rig.clock import MonotonicClock
from rig.devices.trackers._readers import FdReader
from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.serial_tracker import serial_tracker
from rig.devices.trackers.transport import ThreadReader
from rig.emulate.encode import Emission, RecordEncoder

# Long enough never to run out on a loaded machine; a reader that works returns far sooner.
PATIENCE_S = 10.0

class Pipe:
    """Both ends of an os.pipe; each closed once, by the test or afterwards."""

    def __init__(self) -> None:
        self.read_end, self.write_end = os.pipe()
        self._open = {self.read_end, self.write_end}

    def close(self, fd: int) -> None:
        if fd in self._open:
            self._open.remove(fd)
            os.close(fd)


@pytest.fixture
def pipe() -> Iterator[Pipe]:
    made = Pipe()
    yield made
    made.close(made.read_end)
    made.close(made.write_end)


@pytest.fixture(params=["pipe", "pty", "socketpair"])
def descriptors(request: pytest.FixtureRequest) -> Iterator[tuple[int, int]]:
    """(read end, write end) of a pipe, a raw pseudo-terminal (the serial emulator's transport) or a
    socket pair (a TCP port's), closed afterwards."""
    if request.param == "pipe":
        ends = os.pipe()
    elif request.param == "pty":
        leader, follower = pty.openpty()
        tty.setraw(follower)
        ends = (follower, leader)
    else:
        left, right = socket.socketpair()
        ends = (left.detach(), right.detach())
    yield ends
    for fd in ends:
        os.close(fd)


def _take_all(reader: FdReader, size: int) -> tuple[list[bytes], list[float]]:
    """What the reader queues until `size` bytes have come, taken as they come."""
    chunks: list[bytes] = []
    arrivals: list[float] = []
    while sum(map(len, chunks)) < size:
        assert reader.wait(PATIENCE_S), "the reader queued nothing"
        taken, times = reader.take()
        chunks += taken
        arrivals += times
    return chunks, arrivals


def test_the_thread_queues_every_byte_in_order_stamped_on_the_rig_clock(descriptors: tuple[int, int]) -> None:
    read_end, write_end = descriptors
    clock = MonotonicClock()
    reader = FdReader(read_end, clock.origin_ns)
    pieces = [bytes([k]) * (1 + k % 7) for k in range(200)]
    try:
        before = clock.now()
        for piece in pieces:
            os.write(write_end, piece)
        chunks, arrivals = _take_all(reader, sum(map(len, pieces)))
        after = clock.now()
    finally:
        reader.stop()
    assert b"".join(chunks) == b"".join(pieces)
    assert all(chunks), "no empty chunk is queued"
    assert len(arrivals) == len(chunks)
    assert before <= arrivals[0] and arrivals[-1] <= after
    assert arrivals == sorted(arrivals)
    assert reader.outcome == "stopped" and reader.take() == ([], [])


def test_a_stamp_is_the_monotonic_clock_counted_from_the_origin(pipe: Pipe) -> None:
    origin_ns = time.monotonic_ns() - 5 * 10**9
    reader = FdReader(pipe.read_end, origin_ns)
    before_ns = time.monotonic_ns()
    os.write(pipe.write_end, b"x")
    (chunk,), (arrival,) = _take_all(reader, 1)
    after_ns = time.monotonic_ns()
    reader.stop()
    assert chunk == b"x"
    assert (before_ns - origin_ns) / 1e9 <= arrival <= (after_ns - origin_ns) / 1e9


def test_the_end_of_the_file_ends_the_thread_after_what_came_before(pipe: Pipe) -> None:
    reader = FdReader(pipe.read_end, 0)
    os.write(pipe.write_end, b"last words")
    pipe.close(pipe.write_end)
    assert reader.wait_ended(PATIENCE_S)
    assert (reader.outcome, reader.errno) == ("end of file", 0)
    assert b"".join(reader.take()[0]) == b"last words"
    assert reader.wait(0.0), "an ended reader is waited for no longer"
    reader.stop()
    assert reader.outcome == "end of file", "stopping an ended reader leaves how it ended"


def test_a_failed_read_ends_the_thread_with_its_errno(tmp_path) -> None:
    directory = os.open(tmp_path, os.O_RDONLY)
    try:
        reader = FdReader(directory, 0)
        assert reader.wait_ended(PATIENCE_S)
        assert (reader.outcome, reader.errno) == ("error", errno.EISDIR)
        reader.stop()
    finally:
        os.close(directory)


def test_a_closed_descriptor_is_refused(pipe: Pipe) -> None:
    closed = pipe.read_end
    pipe.close(closed)
    with pytest.raises(OSError) as raised:
        FdReader(closed, 0)
    assert raised.value.errno == errno.EBADF


def test_waiting_for_nothing_times_out_and_a_bad_timeout_is_refused(pipe: Pipe) -> None:
    reader = FdReader(pipe.read_end, 0)
    assert not reader.wait(0.0)
    assert not reader.wait(0.01)
    assert not reader.wait_ended(0.0)
    assert reader.outcome is None and reader.take() == ([], [])
    for bad in (-1.0, float("nan")):
        with pytest.raises(ValueError):
            reader.wait(bad)
    reader.stop()


def test_stop_wakes_a_thread_waiting_for_data(pipe: Pipe) -> None:
    reader = FdReader(pipe.read_end, 0)
    assert not reader.wait(0.01), "the thread is waiting: nothing was written"
    stopper = threading.Thread(target=reader.stop)
    stopper.start()
    stopper.join(PATIENCE_S)
    assert not stopper.is_alive(), "stop() did not return"
    assert reader.outcome == "stopped" and reader.wait_ended(0.0)
    reader.stop()


def test_a_dropped_reader_stops_reading_and_its_thread_ends(pipe: Pipe, reader_threads: Callable[[str], set[str]]) -> None:
    before = reader_threads("rig fd reader")
    reader = FdReader(pipe.read_end, 0)
    (started,) = reader_threads("rig fd reader") - before
    del reader
    assert started not in reader_threads("rig fd reader")
    os.write(pipe.write_end, b"after")
    assert os.read(pipe.read_end, 16) == b"after", "nothing reads the descriptor any more"


def test_the_threads_cpu_time_is_kept_once_it_has_ended(pipe: Pipe) -> None:
    reader = FdReader(pipe.read_end, 0)
    os.write(pipe.write_end, b"x")
    _take_all(reader, 1)
    running = reader.cpu_s
    pipe.close(pipe.write_end)
    assert reader.wait_ended(PATIENCE_S)
    ended = reader.cpu_s
    reader.stop()
    assert 0.0 < running <= ended == reader.cpu_s


def _python_reader(pipe: Pipe, origin_ns: int) -> ThreadReader:
    """A ThreadReader of the pipe, as the HID and descriptor-less serial transports make theirs."""

    def receive() -> bytes | None:
        ready, _, _ = select.select([pipe.read_end], [], [], 0.01)
        return os.read(pipe.read_end, 65536) if ready else None

    return ThreadReader(receive, origin_ns, "test python reader")


def test_a_python_reader_queues_every_chunk_in_order_stamped_on_the_rig_clock(pipe: Pipe) -> None:
    clock = MonotonicClock()
    reader = _python_reader(pipe, clock.origin_ns)
    pieces = [bytes([k]) * (1 + k % 5) for k in range(50)]
    before = clock.now()
    for piece in pieces:
        os.write(pipe.write_end, piece)
    chunks, arrivals = _take_all(reader, sum(map(len, pieces)))
    after = clock.now()
    reader.stop()
    assert b"".join(chunks) == b"".join(pieces)
    assert before <= arrivals[0] and arrivals[-1] <= after and arrivals == sorted(arrivals)
    assert (reader.outcome, reader.errno) == ("stopped", 0) and reader.take() == ([], [])


def test_a_python_reader_ends_at_the_end_of_the_link_or_a_failed_read(pipe: Pipe) -> None:
    reader = _python_reader(pipe, 0)
    os.write(pipe.write_end, b"last words")
    pipe.close(pipe.write_end)
    assert reader.wait_ended(PATIENCE_S)
    assert (reader.outcome, reader.errno) == ("end of file", 0)
    assert b"".join(reader.take()[0]) == b"last words"
    reader.stop()

    def fail() -> bytes:
        raise OSError(errno.ENODEV, "unplugged")

    failed = ThreadReader(fail, 0, "test failing reader")
    assert failed.wait_ended(PATIENCE_S) and failed.wait(0.0)
    assert (failed.outcome, failed.errno) == ("error", errno.ENODEV) and failed.cpu_s >= 0.0
    failed.stop()


def test_a_python_reader_waits_for_nothing_until_its_timeout(pipe: Pipe) -> None:
    reader = _python_reader(pipe, 0)
    assert not reader.wait(0.01) and not reader.wait_ended(0.0)
    reader.stop()
    assert reader.outcome == "stopped" and reader.wait_ended(0.0)


class _PipePort:
    """A port with a file descriptor, as pyserial's for a device, a pty or a socket."""

    def __init__(self, fd: int) -> None:
        self._fd = fd

    def fileno(self) -> int:
        return self._fd

    @property
    def in_waiting(self) -> int:
        raise AssertionError("a port with a descriptor is read straight from it")

    def read(self, size: int = 1) -> bytes:
        raise AssertionError("a port with a descriptor is read straight from it")

    def close(self) -> None:
        pass


def _emissions(n: int) -> list[Emission]:
    return [Emission(k, 1.0 + k * 1e-3, (0.01 * k, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0)) for k in range(n)]


def test_a_serial_tracker_reads_every_record_through_the_compiled_thread(pipe: Pipe, reader_threads: Callable[[str], set[str]]) -> None:
    encoder = RecordEncoder(load_profile("binary-pose"))
    sent = _emissions(50)
    tracker = serial_tracker("pipe?profile=binary-pose", open_port=lambda url, baud: _PipePort(pipe.read_end))
    clock = MonotonicClock()
    others = reader_threads("rig fd reader")
    tracker.connect(clock)
    assert reader_threads("rig fd reader") - others, "a port with a descriptor is read by the compiled thread"
    before = clock.now()
    for emission in sent:
        os.write(pipe.write_end, encoder.encode(emission))
    records = []
    while len(records) < len(sent):
        records += tracker.wait_records(PATIENCE_S)
    after = clock.now()
    tracker.close()
    assert [r.seq for r in records] == [e.seq for e in sent]
    assert [r.device_time for r in records] == pytest.approx([e.device_time for e in sent], abs=1e-6)
    assert all(before <= r.t_arrival <= after for r in records)
    assert tracker.report()["counters"]["corrupt"] == 0
    assert tracker.reader_cpu_s > 0.0


def test_a_serial_tracker_reads_records_cut_anywhere_and_its_last_ones_after_close(pipe: Pipe) -> None:
    """On the compiled thread, records split across writes are whole once their last byte came,
    and what was read before close() is still taken after it."""
    encoder = RecordEncoder(load_profile("binary-pose"))
    sent = _emissions(30)
    wire = b"".join(encoder.encode(e) for e in sent)
    tracker = serial_tracker("pipe?profile=binary-pose", open_port=lambda url, baud: _PipePort(pipe.read_end))
    tracker.connect(MonotonicClock())
    for start in range(0, len(wire), 7):
        os.write(pipe.write_end, wire[start : start + 7])
    records = []
    while not records or records[-1].seq < len(sent) - 1:
        records += tracker.wait_records(PATIENCE_S)
    tracker.close()
    records += tracker.take_queued()
    assert [r.seq for r in records] == [e.seq for e in sent]
    assert tracker.report()["counters"]["corrupt"] == 0


def test_a_clock_of_the_tests_own_gets_the_compiled_readers_stamps_on_its_time_line(
    pipe: Pipe, reader_threads: Callable[[str], set[str]]
) -> None:
    """A clock that reads the system's time through a function of the test's (not the system clock's
    own, so its origin is measured): the compiled thread reads all the same, its stamps on that
    clock's time line."""
    clock = MonotonicClock(read_ns=lambda: time.monotonic_ns())
    encoder = RecordEncoder(load_profile("binary-pose"))
    tracker = serial_tracker("pipe?profile=binary-pose", open_port=lambda url, baud: _PipePort(pipe.read_end))
    others = reader_threads("rig fd reader")
    tracker.connect(clock)
    assert reader_threads("rig fd reader") - others
    before = clock.now()
    for emission in _emissions(5):
        os.write(pipe.write_end, encoder.encode(emission))
    records = []
    while len(records) < 5:
        records += tracker.wait_records(PATIENCE_S)
    after = clock.now()
    tracker.close()
    assert [r.seq for r in records] == list(range(5))
    # The two clocks' origins are measured a few microseconds apart: the stamps are within that of the readings around.
    assert all(before - 1e-3 <= r.t_arrival <= after + 1e-3 for r in records)
