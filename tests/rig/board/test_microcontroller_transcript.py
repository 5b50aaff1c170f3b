"""The Microcontroller link against a scripted board: each test pins the protocol as a transcript of
(command, answer) pairs and checks that every pair was used (after pymeasure)."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import pytest
import serial

from rig.board import EncoderEdge, LinkChange, Microcontroller, PhotodiodePassage
from rig.board.framing import FrameDecoder, encode_frame
from rig.board.protocol import protocol
from rig.errors import ConfigError, RigError

SPEC = protocol()
HZ = SPEC["RIG_TICK_HZ"]
OFFSET_S = 1000.0  # board time - rig time
SYNCS = 4
# The counters of a status message, all zero.
ZERO_COUNTERS = dict(rx_frames=0, rx_corrupt=0, rx_unknown=0, rx_overflow=0, tx_dropped=0, event_overflow=0, quad_invalid=0)

Answer = Callable[[int, dict[str, Any], "ScriptedBoard"], list[tuple[str, dict[str, Any]]]]


@dataclass
class Exchange:
    command: str
    fields: dict[str, Any] | None
    answer: Answer


def identity(protocol_version: int = SPEC["RIG_PROTOCOL_VERSION"]) -> Exchange:
    def answer(seq: int, fields: dict[str, Any], board: ScriptedBoard) -> list[tuple[str, dict[str, Any]]]:
        return [
            (
                "RIG_MSG_IDENTITY",
                dict(reply_to=seq, protocol=protocol_version, firmware_major=1, firmware_minor=0, firmware_patch=0,
                     tick_hz=HZ, cpu_hz=16_000_000, name=b"rig-avr\0"),
            )
        ]

    return Exchange("RIG_CMD_IDENTIFY", {}, answer)


def sync() -> Exchange:
    def answer(seq: int, fields: dict[str, Any], board: ScriptedBoard) -> list[tuple[str, dict[str, Any]]]:
        tick = board.tick(board.arrival)
        return [
            ("RIG_MSG_SYNC", dict(reply_to=seq, epoch=tick >> 32, rx_tick=tick & 0xFFFF_FFFF)),
            ("RIG_MSG_SYNC_SENT", dict(reply_to=seq, tx_tick=tick & 0xFFFF_FFFF)),
        ]

    return Exchange("RIG_CMD_SYNC", {}, answer)


def ack(command: str, fields: dict[str, Any] | None = None, status: int = SPEC["RIG_STATUS_OK"]) -> Exchange:
    def answer(seq: int, got: dict[str, Any], board: ScriptedBoard) -> list[tuple[str, dict[str, Any]]]:
        return [("RIG_MSG_ACK", dict(reply_to=seq, command=SPEC.type_id(command), status=status))]

    return Exchange(command, fields, answer)


def status(board_time: float) -> Exchange:
    """A status answer whose clock reads board_time, whatever the scripted clock says."""

    def answer(seq: int, fields: dict[str, Any], board: ScriptedBoard) -> list[tuple[str, dict[str, Any]]]:
        tick = round(board_time * HZ)
        return [("RIG_MSG_STATUS", dict(reply_to=seq, unsolicited=0, epoch=tick >> 32, tick=tick & 0xFFFF_FFFF, stream=0) | ZERO_COUNTERS)]

    return Exchange("RIG_CMD_STATUS", {}, answer)


def silent(command: str) -> Exchange:
    return Exchange(command, None, lambda seq, fields, board: [])


def connecting() -> list[Exchange]:
    return [identity()] + [sync() for _ in range(SYNCS)]


@dataclass
class ScriptedBoard:
    """A serial port with a board behind it that answers from a transcript; its clock runs
    OFFSET_S ahead of time.monotonic()."""

    transcript: list[Exchange]
    used: int = 0
    closed: bool = False
    broken: bool = False
    mismatch: str | None = None
    arrival: float = 0.0
    _waiting: list[tuple[float, bytes]] = field(default_factory=list)
    _ready: threading.Condition = field(default_factory=threading.Condition)
    _decoder: FrameDecoder = field(default_factory=lambda: FrameDecoder(SPEC, accepted_prefix="RIG_CMD_"))
    _seq: int = 0

    def tick(self, at: float | None = None) -> int:
        return round(((time.monotonic() if at is None else at) + OFFSET_S) * HZ)

    def send(self, message: str, fields: dict[str, Any], at: float = 0.0) -> None:
        type_id = SPEC.type_id(message)
        self.send_bytes(encode_frame(type_id, self._seq, SPEC.layout(type_id).pack(**fields), SPEC), at)
        self._seq = (self._seq + 1) % 256

    def send_bytes(self, data: bytes, at: float = 0.0) -> None:
        """Bytes for the host, which it can read from rig time `at` on."""
        with self._ready:
            self._waiting.append((at, data))
            self._ready.notify_all()

    def _arrived(self) -> bytes:
        now = time.monotonic()
        ready = b"".join(data for at, data in self._waiting if at <= now)
        self._waiting = [(at, data) for at, data in self._waiting if at > now]
        return ready

    # The part of pyserial's interface the link uses.
    @property
    def in_waiting(self) -> int:
        return 0

    def read(self, size: int = 1) -> bytes:
        deadline = time.monotonic() + 0.05
        with self._ready:
            while True:
                if self.broken:
                    raise serial.SerialException("device reports readiness to read but returned no data")
                data = self._arrived()
                left = deadline - time.monotonic()
                if data or self.closed or left <= 0:
                    return data
                soonest = min((at for at, _ in self._waiting), default=deadline)
                self._ready.wait(min(left, max(soonest - time.monotonic(), 0.0)))

    def write(self, data: bytes) -> int:
        # The bytes take their time on the line: the board has them, and answers, only then.
        self.arrival = time.monotonic() + len(data) * SPEC["RIG_UART_BITS_PER_BYTE"] / SPEC["RIG_BAUD"]
        for frame in self._decoder.feed(data):
            name = SPEC.type_names[frame.type]
            fields = SPEC.layout(frame.type).unpack(frame.payload)
            if self.used == len(self.transcript):
                self.mismatch = f"unexpected {name} after the transcript"
                continue
            expected = self.transcript[self.used]
            if name != expected.command or (expected.fields is not None and fields != expected.fields):
                self.mismatch = f"exchange {self.used}: got {name} {fields}, expected {expected.command} {expected.fields}"
                continue
            self.used += 1
            for message, answer_fields in expected.answer(frame.seq, fields, self):
                self.send(message, answer_fields, at=self.arrival)
        return len(data)

    def reset_input_buffer(self) -> None:
        with self._ready:
            self._waiting.clear()

    def close(self) -> None:
        with self._ready:
            self.closed = True
            self._ready.notify_all()

    def break_line(self) -> None:
        with self._ready:
            self.broken = True
            self._ready.notify_all()

    def check_all_used(self) -> None:
        assert self.mismatch is None, self.mismatch
        assert self.used == len(self.transcript), f"only {self.used} of {len(self.transcript)} exchanges used"


class Events:
    def __init__(self) -> None:
        self.events: list[object] = []

    def on_event(self, event: object) -> None:
        self.events.append(event)

    def on_batch_end(self) -> None:
        pass

    def of(self, kind: type) -> list[Any]:
        return [event for event in self.events if isinstance(event, kind)]


def wait_for(condition: Callable[[], bool], timeout: float = 5.0) -> None:
    deadline = time.monotonic() + timeout
    pause = threading.Event()
    while not condition():
        assert time.monotonic() < deadline, "timed out"
        pause.wait(0.01)


def link_to(*boards: ScriptedBoard, **options: Any) -> Microcontroller:
    ports = iter(boards)
    defaults = dict(sync_round_trips=SYNCS, reply_timeout_s=0.2, reconnect_timeout_s=2.0, boot_s=0.0)
    return Microcontroller("scripted://board", open_port=lambda url: next(ports), **(defaults | options))


def test_the_constructor_opens_nothing() -> None:
    opened = []
    link = Microcontroller("scripted://board", open_port=lambda url: opened.append(url))
    assert opened == [] and link.identity is None


def test_connect_identifies_the_board_and_synchronises_the_clocks() -> None:
    board = ScriptedBoard(connecting() + [ack("RIG_CMD_LED", {"level": 128})])
    with link_to(board) as link:
        link.set_led(128)
        interval = link.clock_model.latest
    board.check_all_used()
    assert link.identity.name == "rig-avr" and link.identity.firmware == "1.0.0"
    assert interval.low <= OFFSET_S <= interval.high
    assert interval.width < 0.05


def test_a_board_speaking_another_protocol_is_refused_and_the_link_closed() -> None:
    board = ScriptedBoard([identity(protocol_version=SPEC["RIG_PROTOCOL_VERSION"] + 1)])
    with pytest.raises(RigError, match="flash the firmware"):
        link_to(board).connect()
    assert board.closed


def test_a_refused_command_raises_with_the_reason() -> None:
    refusal = ack("RIG_CMD_PHOTODIODE", {"rise": 600, "fall": 400, "raw_every": 0}, status=SPEC["RIG_STATUS_BAD_VALUE"])
    board = ScriptedBoard(connecting() + [refusal])
    with link_to(board) as link:
        with pytest.raises(RigError, match="refused RIG_CMD_PHOTODIODE: bad value"):
            link.configure_photodiode(600, 400)
    board.check_all_used()


def test_an_unanswered_command_is_asked_again() -> None:
    board = ScriptedBoard(connecting() + [silent("RIG_CMD_STREAM"), ack("RIG_CMD_STREAM", {"mask": SPEC["RIG_STREAM_ENCODER"]})])
    with link_to(board) as link:
        link.stream(encoder=True)
    board.check_all_used()


def test_a_board_that_never_answers_gives_a_clear_error() -> None:
    board = ScriptedBoard([silent("RIG_CMD_IDENTIFY")] * 2)
    with pytest.raises(RigError, match="did not answer RIG_CMD_IDENTIFY .2 tries"):
        link_to(board, tries=2, reply_timeout_s=0.05).connect()
    board.check_all_used()


def test_a_board_still_booting_is_waited_for() -> None:
    board = ScriptedBoard([silent("RIG_CMD_IDENTIFY")] * 3 + connecting())
    with link_to(board, tries=1, reply_timeout_s=0.05, boot_s=0.2):
        pass
    board.check_all_used()


def test_loop_url_has_no_board_behind_it() -> None:
    with pytest.raises(RigError, match="did not answer"):
        Microcontroller("loop://", tries=1, reply_timeout_s=0.05, boot_s=0.0).connect()


def test_values_are_checked_before_anything_is_sent() -> None:
    link = Microcontroller("scripted://board", open_port=lambda url: pytest.fail("opened"))
    with pytest.raises(ConfigError, match="0..255"):
        link.set_led(256)
    with pytest.raises(ConfigError, match="fall < rise"):
        link.configure_photodiode(400, 400)
    with pytest.raises(ConfigError, match="every edge"):
        link.configure_encoder(-1.0)
    with pytest.raises(ConfigError, match="raw_every"):
        link.configure_photodiode(600, 400, raw_every=2)
    with pytest.raises(ConfigError):
        Microcontroller("x", tries=0)


def test_events_are_placed_on_the_full_board_time_line_and_the_rig_clock() -> None:
    board = ScriptedBoard(connecting())
    events = Events()
    with link_to(board) as link:
        link.add_listener(events)
        anchor = (3 << 32) | 0xFFFF_FF00
        board.send("RIG_MSG_STATUS", dict(reply_to=0, unsolicited=1, epoch=3, tick=0xFFFF_FF00, stream=1) | ZERO_COUNTERS)
        board.send("RIG_MSG_ENCODER", dict(tick=0xFFFF_FFF0, count=-5, edges=1, step=-1))
        board.send("RIG_MSG_ENCODER", dict(tick=0x0000_0010, count=-6, edges=1, step=-1))
        board.send("RIG_MSG_PASSAGE", dict(start_tick=0xFFFF_FFFE, centroid_tick=0x20, end_tick=0x40, peak=700))
        wait_for(lambda: len(events.of(PhotodiodePassage)) == 1)
        offset = link.clock_model.offset_at(time.monotonic())
    edges = events.of(EncoderEdge)
    assert [edge.board_tick for edge in edges] == [anchor + 0xF0, anchor + 0x110]
    assert [(edge.count, edge.step) for edge in edges] == [(-5, -1), (-6, -1)]
    assert edges[1].board_time == pytest.approx((anchor + 0x110) / HZ)
    assert edges[1].rig_time == pytest.approx(edges[1].board_time - offset, abs=1e-9)
    passage = events.of(PhotodiodePassage)[0]
    assert (passage.start_tick, passage.board_tick, passage.end_tick) == (anchor + 0xFE, anchor + 0x120, anchor + 0x140)


def test_waiting_for_board_time_asks_the_board_until_its_clock_gets_there() -> None:
    board = ScriptedBoard(connecting() + [status(9.2), status(9.7), status(10.05)])
    with link_to(board) as link:
        link.wait_for_board_time(10.0, limit_s=5.0, poll_s=0.0)
    board.check_all_used()


def test_a_board_clock_that_stands_still_is_reported() -> None:
    board = ScriptedBoard(connecting() + [status(9.2)])
    with link_to(board) as link:
        with pytest.raises(RigError, match="board's clock reads 9.200 s, still short of 10.000 s after -1 s"):
            link.wait_for_board_time(10.0, limit_s=-1.0)
    board.check_all_used()


def test_bad_frames_are_counted_and_skipped() -> None:
    board = ScriptedBoard(connecting())
    events = Events()
    with link_to(board) as link:
        link.add_listener(events)
        board.send_bytes(b"\x07noise\x00\x01\x00")
        board.send_bytes(encode_frame(0x7E, 200, b"", SPEC))
        board.send("RIG_MSG_LED", dict(tick=5, level=255, bit=0))
        wait_for(lambda: events.events)
        counters = link.counters
    assert counters["corrupt"] + counters["truncated"] == 2 and counters["unknown"] == 1


def test_a_dropped_line_is_reopened_and_the_board_set_up_again() -> None:
    stream = ack("RIG_CMD_STREAM", {"mask": SPEC["RIG_STREAM_ENCODER"]})
    encoder = ack("RIG_CMD_ENCODER", {"report_ticks": 0})
    first = ScriptedBoard(connecting() + [encoder, stream])
    second = ScriptedBoard(connecting() + [encoder, stream])
    events = Events()
    with link_to(first, second) as link:
        link.add_listener(events)
        link.configure_encoder(0)
        link.stream(encoder=True)
        first.break_line()
        wait_for(lambda: [e.kind for e in events.of(LinkChange)] == ["lost", "restored", "configured"])
        second.send("RIG_MSG_ENCODER", dict(tick=10, count=1, edges=1, step=1))
        wait_for(lambda: events.of(EncoderEdge))
        assert link.counters["reconnects"] == 1
    first.check_all_used()
    second.check_all_used()
    assert first.closed and second.closed


def test_a_line_that_cannot_be_reopened_fails_the_link() -> None:
    board = ScriptedBoard(connecting())

    def open_port(url: str) -> ScriptedBoard:
        if board.broken:
            raise serial.SerialException(f"could not open port {url}")
        return board

    link = Microcontroller("scripted://board", open_port=open_port, sync_round_trips=SYNCS, reconnect_timeout_s=0.2, boot_s=0.0)
    def failed() -> bool:
        try:
            link.check()
        except RigError:
            return True
        return False

    with link:
        board.break_line()
        wait_for(failed)
        with pytest.raises(RigError, match="could not reopen it within 0.2 s"):
            link.check()
        with pytest.raises(RigError, match="could not reopen"):
            link.status()
