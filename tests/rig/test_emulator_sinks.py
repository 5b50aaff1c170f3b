"""The emulator's serial sinks through a real pseudo-terminal and a real socket (socket://), and its
sending loop on a fake clock: it never waits on a reader that is not reading, never tears a record,
keeps nothing for a reader that has not connected, ends when its reader hangs up, and gives up
waiting for one after its idle timeout. No test waits on the wall clock."""

from __future__ import annotations

import errno
import os
import socket
from pathlib import Path
from types import SimpleNamespace
from typing import Iterator, Sequence

import numpy as np
import pytest

from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.serial_tracker import DEFAULT_PROFILE, parse_serial_address
from rig.emulate import EmulatorConfig, streamer
from rig.emulate.encode import Emission, RecordEncoder
from rig.emulate.outbox import Outbox
from rig.emulate.sinks import PtySink, TcpSink
from rig.emulate.streamer import ReaderGone, SentCounts, stream
from rig.errors import ConfigError
from rig.sim.tracker import TrackerSamples
from rig.sim.tracker_faults import ByteFaults, FaultPlan

ENCODER = RecordEncoder(load_profile("binary-pose"))
# Enough records to fill any pty's or loopback socket's buffers many times over.
MANY = 4000


def _emissions(first: int, count: int) -> list[Emission]:
    return [Emission(seq, seq * 1e-3, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)) for seq in range(first, first + count)]


def _no_sleep(seconds: float) -> None:
    """The sinks' pause after a reader connects, skipped: these tests wait on nothing."""


def _fill(sink: PtySink | TcpSink) -> list[Emission]:
    """Sends records a few at a time until the port takes fewer than offered; the ones it took."""
    taken: list[Emission] = []
    for first in range(0, MANY, 8):
        batch = _emissions(first, 8)
        damaged, _ = sink.send(batch, 1000.0)
        taken += batch[: len(damaged)]
        if len(damaged) < len(batch):
            return taken
    pytest.fail(f"the port took all {MANY} records: the test needs a reader that falls behind")


def _read_all(fd: int) -> bytes:
    """Everything waiting on a non-blocking descriptor."""
    data = b""
    while True:
        try:
            chunk = os.read(fd, 1 << 16)
        except BlockingIOError:
            return data
        if not chunk:
            return data
        data += chunk


@pytest.fixture
def pty_sink(tmp_path: Path) -> Iterator[PtySink]:
    sink = PtySink(tmp_path / "tracker", ENCODER, ByteFaults(FaultPlan(), 0), sleep=_no_sleep, write_wait_s=0.0)
    yield sink
    sink.close()


@pytest.fixture
def tcp_sink() -> Iterator[TcpSink]:
    sink = TcpSink(0, ENCODER, ByteFaults(FaultPlan(), 0), sleep=_no_sleep, write_wait_s=0.0, send_buffer_bytes=4096)
    yield sink
    sink.close()


def _open_reader(sink: PtySink) -> int:
    return os.open(sink.link, os.O_RDONLY | os.O_NOCTTY | os.O_NONBLOCK)


def test_a_pty_reader_that_falls_behind_is_not_waited_on_and_gets_whole_records_in_order(pty_sink: PtySink) -> None:
    reader = _open_reader(pty_sink)
    try:
        assert pty_sink.wait_for_reader(stop_at=0.0)
        taken = _fill(pty_sink)
        received = _read_all(reader)
        more = _emissions(MANY, 1)
        damaged, _ = pty_sink.send(more, 1000.0)
        assert damaged == [False], "once read, the port takes records again (the rest of one it took in part first)"
        received += _read_all(reader)
    finally:
        os.close(reader)
    assert received == b"".join(ENCODER.encode(e) for e in taken + more)
    assert len(taken) < MANY // 4, "what waits for a slow reader is what the terminal's buffer holds, not every record"


def test_a_pty_whose_reader_hung_up_ends_the_stream(pty_sink: PtySink) -> None:
    reader = _open_reader(pty_sink)
    assert pty_sink.wait_for_reader(stop_at=0.0)
    pty_sink.send(_emissions(0, 3), 1000.0)
    os.close(reader)
    with pytest.raises(ReaderGone):
        pty_sink.send(_emissions(3, 1), 1000.0)


def test_a_pty_without_a_reader_is_not_waited_on_past_its_deadline(pty_sink: PtySink) -> None:
    assert not pty_sink.wait_for_reader(stop_at=0.0)


def _connect(sink: TcpSink) -> socket.socket:
    host, port = parse_serial_address(sink.address)[0].removeprefix("socket://").split(":")
    client = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    client.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # a reader that falls behind soon
    client.connect((host, int(port)))
    assert sink.wait_for_reader(stop_at=float("inf"))
    return client


def _receive_until_closed(client: socket.socket) -> bytes:
    data = b""
    while chunk := client.recv(1 << 16):
        data += chunk
    return data


def test_a_socket_reader_that_falls_behind_is_not_waited_on_and_gets_whole_records_in_order(tcp_sink: TcpSink) -> None:
    client = _connect(tcp_sink)
    with client:
        taken = _fill(tcp_sink)
        more = _emissions(MANY, 1)
        received = client.recv(1 << 16)
        while not tcp_sink.send(more, 1000.0)[0]:  # sent once the socket has room again
            received += client.recv(1 << 16)
        tcp_sink.close()
        received += _receive_until_closed(client)
    assert received == b"".join(ENCODER.encode(e) for e in taken + more)
    assert len(taken) < MANY, "records that found the socket full were not queued"


def test_a_socket_whose_client_closed_ends_the_stream(tcp_sink: TcpSink) -> None:
    client = _connect(tcp_sink)
    tcp_sink.send(_emissions(0, 3), 1000.0)
    client.close()
    with pytest.raises(ReaderGone):
        for first in range(3, 100):  # the close may reach the server only after a write or two
            tcp_sink.send(_emissions(first, 1), 1000.0)


class PortThatTakes:
    """A non-blocking port taking `room` bytes, then none (BlockingIOError) until given more room;
    asked whether it has room, it gives `later` more bytes of it (once) and says so."""

    def __init__(self, room: int, later: int = 0) -> None:
        self.room = room
        self.later = later
        self.data = b""
        self.waits: list[float] = []

    def write(self, data: bytes) -> int:
        if self.room == 0:
            raise BlockingIOError(errno.EAGAIN, "full")
        taken = data[: self.room]
        self.room -= len(taken)
        self.data += taken
        return len(taken)

    def writable(self, timeout_s: float) -> bool:
        self.waits.append(timeout_s)
        self.room, self.later = self.room + self.later, 0
        return self.room > 0


def _outbox(port: PortThatTakes) -> Outbox:
    return Outbox(port.write, port.writable, wait_s=1.0, clock=lambda: 0.0)


def test_the_outbox_waits_for_room_to_finish_a_record() -> None:
    port = PortThatTakes(room=6, later=100)
    assert _outbox(port).send([b"abcd", b"efgh", b"ijkl"]) == 3
    assert port.data == b"abcdefghijkl" and port.waits == [1.0], "one wait, for the rest of the second"


def test_a_record_taken_in_part_is_finished_before_anything_else_and_none_is_waited_for_meanwhile() -> None:
    port = PortThatTakes(room=6)
    outbox = _outbox(port)
    assert outbox.send([b"abcd", b"efgh", b"ijkl"]) == 2, "the second record went in part: taken, its rest kept"
    assert port.data == b"abcdef"
    assert outbox.send([b"mnop"]) == 0, "no room for the rest: nothing new is sent"
    assert port.waits == [1.0], "no wait once stalled"
    port.room = 5
    assert outbox.send([b"qrst", b"uvwx"]) == 1
    assert port.data == b"abcdefghqrs", "the rest first, then what fits"
    port.room = 100
    assert outbox.send([b"yz"]) == 1
    assert port.data == b"abcdefghqrstyz"


def test_a_record_that_found_no_room_is_never_sent_later() -> None:
    port = PortThatTakes(room=4)
    outbox = _outbox(port)
    assert outbox.send([b"abcd", b"efgh"]) == 1
    port.room = 100
    assert outbox.send([b"ijkl"]) == 1
    assert port.data == b"abcdijkl"


class ScriptedSink:
    """A sink that finds a reader (or not) and takes the first `takes[i]` records of its i-th send."""

    address = "scripted"

    def __init__(self, reader: bool, takes: Sequence[int] = ()) -> None:
        self.reader = reader
        self.takes = list(takes)
        self.deadline: float | None = None
        self.lingered: float | None = None

    def wait_for_reader(self, stop_at: float) -> bool:
        self.deadline = stop_at
        return self.reader

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]:
        if not self.takes:
            raise ReaderGone
        return [False] * min(self.takes.pop(0), len(emissions)), 0.0

    def disconnect(self) -> None: ...

    def reconnect(self, stop_at: float) -> bool:
        return False

    def linger(self, seconds: float) -> None:
        self.lingered = seconds

    def close(self) -> None: ...


@pytest.fixture
def fake_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """The sending loop on a clock that stands at 100 s and never waits."""
    monkeypatch.setattr(streamer, "time", SimpleNamespace(monotonic=lambda: 100.0, sleep=lambda seconds: None))


def _samples(count: int, step_s: float) -> tuple[TrackerSamples, np.ndarray]:
    t = np.arange(count) * step_s
    orientations = np.tile([1.0, 0.0, 0.0, 0.0], (count, 1))
    samples = TrackerSamples(seq=np.arange(count), t_sensor=t, t_arrival=t, positions=np.zeros((count, 3)), orientations=orientations,
                             lost=np.zeros(count, dtype=bool))  # fmt: skip
    return samples, np.zeros((count, 3))


def _stream(sink: ScriptedSink, count: int, step_s: float = 0.0, idle_timeout_s: float = 60.0) -> tuple[SentCounts, list[str]]:
    """Streams `count` samples due `step_s` apart (records due at once go in one write)."""
    events: list[str] = []
    samples, rates = _samples(count, step_s)
    counts = stream(samples, rates, sink, 1000.0, None, lambda t: t, None, events.append, idle_timeout_s=idle_timeout_s)
    return counts, events


def test_no_reader_within_the_idle_timeout_sends_nothing(fake_time: None) -> None:
    sink = ScriptedSink(reader=False)
    counts, events = _stream(sink, 10, idle_timeout_s=2.5)
    assert sink.deadline == 102.5
    assert counts == SentCounts() and events == ["no reader came in 2.5 s; nothing sent"]


def test_records_the_port_did_not_take_are_counted_unread_and_the_stream_ends_when_the_reader_goes(fake_time: None) -> None:
    sink = ScriptedSink(reader=True, takes=[4])
    counts, _ = _stream(sink, 10)
    assert (counts.intact, counts.unread, counts.sent) == (4, 6, 4)
    assert sink.lingered == streamer.DRAIN_S, "once all is sent, the reader may take what is in flight"
    counts, events = _stream(ScriptedSink(reader=True, takes=[1, 0, 1]), 10, step_s=1e-3)
    assert (counts.intact, counts.unread, counts.lost) == (2, 1, 0)
    assert events[-1] == "the reader went away; stopping"


def test_the_emulator_sends_what_the_recorder_reads_by_default() -> None:
    assert EmulatorConfig("pty", "/tmp/x").profile == DEFAULT_PROFILE == parse_serial_address("/dev/ttyUSB0")[1]


@pytest.mark.parametrize("seconds", [0.0, -1.0, float("nan")])
def test_an_idle_timeout_outside_its_range_is_refused(seconds: float) -> None:
    with pytest.raises(ConfigError, match="idle_timeout_s"):
        EmulatorConfig("pty", "/tmp/x", idle_timeout_s=seconds)
