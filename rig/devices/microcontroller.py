"""The rig's microcontroller, over a serial link: identity, clock sync, LED, encoder and photodiode.

`Microcontroller(url)` only remembers where the board is; `connect()` (or `with`) opens the port
through `serial.serial_for_url` (a /dev/tty... path, the emulated board's pty, `loop://`, or any
opener passed in), starts a reader thread that decodes frames as they arrive, asks the board who it
is and synchronises the clocks. Every event goes to the listeners as it arrives, with its board
time converted to the rig clock. If the link drops, the reader reopens the port, and a keeper
thread synchronises again and restores the board's configuration; nothing received before is lost.
"""

from __future__ import annotations

import itertools
import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Protocol

import serial

from rig.devices.blink_code import BlinkSchedule
from rig.devices.board_events import (
    BoardEvent,
    BoardIdentity,
    BoardStatus,
    ClockSynced,
    EncoderEdge,
    LedChange,
    LinkChange,
    PhotodiodeCrossing,
    PhotodiodePassage,
    PhotodiodeSample,
)
from rig.devices.clock_sync import ClockModel, OffsetInterval, RoundTrip, TickUnwrapper, narrow
from rig.devices.framing import FrameDecoder, LinkCounters, encode_frame
from rig.devices.protocol import ProtocolSpec, protocol
from rig.errors import ConfigError, RigError

# How long one read waits for bytes, so that the reader notices close() promptly.
READ_TIMEOUT_S = 0.05
# After a reconnection, setting the board up again is tried this often, this far apart.
RESTORE_TRIES = 5
RESTORE_RETRY_S = 0.5
RECONNECT_FIRST_WAIT_S = 0.05
RECONNECT_LONGEST_WAIT_S = 0.5


class SerialPort(Protocol):
    """What the link needs of a pyserial port."""

    @property
    def in_waiting(self) -> int: ...

    def read(self, size: int = 1) -> bytes: ...

    def write(self, data: bytes) -> int | None: ...

    def reset_input_buffer(self) -> None: ...

    def close(self) -> None: ...


class BoardListener(Protocol):
    """Receives the board's events on the reader thread; on_batch_end follows each batch of
    events that arrived together (the moment to flush a file)."""

    def on_event(self, event: BoardEvent) -> None: ...

    def on_batch_end(self) -> None: ...


def open_serial_url(url: str) -> SerialPort:
    """The default opener: pyserial's serial_for_url at the protocol's baud rate."""
    return serial.serial_for_url(url, baudrate=protocol()["RIG_BAUD"], timeout=READ_TIMEOUT_S, write_timeout=1.0)


@dataclass(frozen=True)
class _Answer:
    """The answers to one command, by message type, and when the command was sent and each answer
    arrived (rig clock)."""

    spec: ProtocolSpec
    sent: float
    answers: dict[int, dict[str, Any]]
    received: dict[int, float]

    def answer(self, name: str) -> dict[str, Any]:
        return self.answers[self.spec.type_id(name)]

    def received_at(self, name: str) -> float:
        return self.received[self.spec.type_id(name)]


class _LinkDown(Exception):
    """The port is closed or failed while writing; the reader thread is reconnecting."""


@dataclass
class _Pending:
    """A command waiting for its answers: every message type in `expects`, or an ACK."""

    expects: tuple[int, ...]
    done: threading.Event = field(default_factory=threading.Event)
    answers: dict[int, dict[str, Any]] = field(default_factory=dict)
    received: dict[int, float] = field(default_factory=dict)
    ack_status: int | None = None
    link_lost: bool = False


class Microcontroller:
    """The rig board behind a serial URL. See the module docstring for the threads it runs.

    open_port: opens the URL (default: pyserial's serial_for_url); tests pass their own.
    clock: the rig clock, seconds; event times are converted to it.
    reply_timeout_s, tries: how long to wait for each answer, and how often to ask.
    boot_s: how long the board may take to answer once its port is open (an Arduino resets when
        its port opens, and its bootloader waits about a second before starting the firmware).
    reconnect_timeout_s: how long to keep trying to reopen a dropped port before giving up.
    sync_round_trips: round trips per clock synchronisation.
    resync_every_s: synchronise again this often while connected (None: only on connect and
        reconnect), which shows drift.
    """

    def __init__(
        self,
        url: str,
        *,
        open_port: Callable[[str], SerialPort] = open_serial_url,
        clock: Callable[[], float] = time.monotonic,
        reply_timeout_s: float = 0.25,
        tries: int = 3,
        boot_s: float = 2.5,
        reconnect_timeout_s: float = 5.0,
        sync_round_trips: int = 48,
        resync_every_s: float | None = None,
    ) -> None:
        if reply_timeout_s <= 0 or reconnect_timeout_s <= 0:
            raise ConfigError("reply_timeout_s and reconnect_timeout_s must be positive")
        if boot_s < 0:
            raise ConfigError(f"boot_s must be >= 0, got {boot_s}")
        if tries < 1 or sync_round_trips < 4:
            raise ConfigError(f"tries must be >= 1 and sync_round_trips >= 4, got {tries} and {sync_round_trips}")
        if resync_every_s is not None and resync_every_s <= 0:
            raise ConfigError(f"resync_every_s must be positive, got {resync_every_s}")
        self.url = url
        self._open_port = open_port
        self._clock = clock
        self._reply_timeout = reply_timeout_s
        self._tries = tries
        self._boot_tries = max(tries, math.ceil(boot_s / reply_timeout_s))
        self._reconnect_timeout = reconnect_timeout_s
        self._sync_round_trips = sync_round_trips
        self._resync_every = resync_every_s
        self._port: SerialPort | None = None
        self._port_lock = threading.Lock()
        self._pending: dict[int, _Pending] = {}
        self._pending_lock = threading.Lock()
        self._seq = itertools.count(1)
        self._decoder: FrameDecoder | None = None
        self._unwrapper = TickUnwrapper()
        self._clock_model = ClockModel()
        self._clock_lock = threading.Lock()
        self._listeners: list[BoardListener] = []
        self._listener_lock = threading.RLock()
        self._stop = threading.Event()
        self._link_up = threading.Event()
        self._restore_needed = threading.Event()
        self._failure: RigError | None = None
        self._config: dict[str, dict[str, int]] = {}
        self._identity: BoardIdentity | None = None
        self._reconnects = 0
        self._threads: list[threading.Thread] = []

    # ---- connection ----

    def connect(self) -> BoardIdentity:
        """Opens the port, identifies the board and synchronises the clocks."""
        if self._threads:
            raise RigError(f"already connected to {self.url}")
        self._decoder = FrameDecoder(self.spec)
        self._stop.clear()
        self._failure = None
        self._port = self._open()
        self._link_up.set()
        self._start_thread(self._read_loop, "board-reader")
        try:
            identity = self.identify(tries=self._boot_tries)
            self.sync()
        except BaseException:
            self.close()
            raise
        self._start_thread(self._keep_loop, "board-keeper")
        return identity

    def close(self) -> None:
        """Stops the threads and closes the port; safe to call more than once."""
        self._stop.set()
        self._restore_needed.set()
        with self._port_lock:
            port, self._port = self._port, None
            self._link_up.clear()
        if port is not None:
            _close_quietly(port)
        self._fail_pending()
        for thread in self._threads:
            thread.join()
        self._threads = []

    def __enter__(self) -> Microcontroller:
        self.connect()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def _start_thread(self, target: Callable[[], None], name: str) -> None:
        thread = threading.Thread(target=target, name=f"{name} {self.url}", daemon=True)
        self._threads.append(thread)
        thread.start()

    def _open(self) -> SerialPort:
        try:
            port = self._open_port(self.url)
            port.reset_input_buffer()
        except (serial.SerialException, OSError, ValueError) as error:
            raise RigError(f"cannot open the board's serial port {self.url}: {error}; check the cable and --port") from None
        return port

    # ---- state ----

    @property
    def spec(self) -> ProtocolSpec:
        return protocol()

    @property
    def identity(self) -> BoardIdentity | None:
        return self._identity

    @property
    def counters(self) -> dict[str, int]:
        """The host's link counters (see LinkCounters) and the number of reconnections."""
        counters = self._decoder.counters.as_dict() if self._decoder else LinkCounters().as_dict()
        return counters | {"reconnects": self._reconnects}

    @property
    def clock_model(self) -> ClockModel:
        return self._clock_model

    def to_rig_time(self, board_time: float) -> float:
        """The rig time of a board time (NaN before the first clock synchronisation)."""
        with self._clock_lock:
            if self._clock_model.latest is None:
                return math.nan
            return self._clock_model.to_rig_time(board_time)

    def board_time_now(self) -> float:
        """The board's time now, from the rig clock and the latest offset."""
        with self._clock_lock:
            latest = self._clock_model.latest
            if latest is None:
                raise RigError("the board clock is not synchronised yet")
            now = self._clock()
            return now + self._clock_model.offset_at(now)

    def check(self) -> None:
        """Raises the error that stopped the link (the port could not be reopened, or a listener
        could not write), if any."""
        if self._failure is not None:
            raise self._failure

    def add_listener(self, listener: BoardListener) -> None:
        with self._listener_lock:
            self._listeners.append(listener)

    def remove_listener(self, listener: BoardListener) -> None:
        with self._listener_lock:
            self._listeners.remove(listener)

    # ---- commands ----

    def identify(self, tries: int | None = None) -> BoardIdentity:
        answer = self._request("RIG_CMD_IDENTIFY", expects=("RIG_MSG_IDENTITY",), tries=tries)
        fields = answer.answer("RIG_MSG_IDENTITY")
        spec = self.spec
        identity = BoardIdentity(
            name=fields["name"].rstrip(b"\0").decode("ascii", "replace"),
            protocol=fields["protocol"],
            firmware=f"{fields['firmware_major']}.{fields['firmware_minor']}.{fields['firmware_patch']}",
            tick_hz=fields["tick_hz"],
            cpu_hz=fields["cpu_hz"],
        )
        if identity.protocol != spec["RIG_PROTOCOL_VERSION"] or identity.tick_hz != spec["RIG_TICK_HZ"]:
            raise RigError(
                f"the board at {self.url} speaks protocol {identity.protocol} at {identity.tick_hz} Hz, this rig "
                f"protocol {spec['RIG_PROTOCOL_VERSION']} at {spec['RIG_TICK_HZ']} Hz: "
                "flash the firmware of this checkout (make -C firmware flash)"
            )
        self._identity = identity
        return identity

    def status(self) -> BoardStatus:
        fields = self._request("RIG_CMD_STATUS", expects=("RIG_MSG_STATUS",)).answer("RIG_MSG_STATUS")
        return self._status_event(fields, (fields["epoch"] << 32) | fields["tick"])

    def wait_for_board_time(self, board_time: float, limit_s: float, poll_s: float = 0.02) -> None:
        """Waits until the board's own clock, asked rather than estimated, has passed `board_time`;
        raises RigError after `limit_s`. A board behind the wall clock (an emulator on a busy
        machine) would otherwise still be doing what the caller believes is done."""
        deadline = time.monotonic() + limit_s
        pause = threading.Event()
        while (now := self.status().board_time) < board_time:
            if time.monotonic() > deadline:
                raise RigError(
                    f"the board's clock reads {now:.3f} s, still short of {board_time:.3f} s after "
                    f"{limit_s:g} s: is the board running?"
                )
            pause.wait(min(poll_s, board_time - now))

    def sync(self, round_trips: int | None = None) -> OffsetInterval:
        """Measures the clock offset: intersects the intervals of `round_trips` round trips."""
        spec = self.spec
        count = self._sync_round_trips if round_trips is None else round_trips
        if count < 1:
            raise ConfigError(f"round_trips must be >= 1, got {count}")
        byte_time = spec["RIG_UART_BITS_PER_BYTE"] / spec["RIG_BAUD"]
        request_bytes = len(encode_frame(spec["RIG_CMD_SYNC"], 0, b"", spec))
        intervals: list[OffsetInterval] = []
        for _ in range(count):
            try:
                answer = self._request("RIG_CMD_SYNC", expects=("RIG_MSG_SYNC", "RIG_MSG_SYNC_SENT"), tries=1)
            except RigError:
                self.check()
                continue
            reply, sent_at = answer.answer("RIG_MSG_SYNC"), answer.answer("RIG_MSG_SYNC_SENT")
            board_rx = (reply["epoch"] << 32) | reply["rx_tick"]
            board_tx = board_rx + ((sent_at["tx_tick"] - reply["rx_tick"]) % TickUnwrapper.WRAP)
            hz = spec["RIG_TICK_HZ"]
            trip = RoundTrip(answer.sent, answer.received_at("RIG_MSG_SYNC"), board_rx / hz, board_tx / hz)
            intervals.append(trip.bounds(request_bytes, byte_time))
        if len(intervals) < min(count, 3):
            raise RigError(f"clock sync failed: the board answered {len(intervals)} of {count} round trips")
        try:
            interval, left_out = narrow(intervals)
        except ValueError:
            raise RigError(
                "clock sync failed: the board answered faster than its bytes can travel at "
                f"{spec['RIG_BAUD']} baud; is it running the rig firmware at that rate?"
            ) from None
        with self._clock_lock:
            self._clock_model.add(interval)
        self._emit(ClockSynced(self._clock(), interval.low, interval.high, interval.round_trips, left_out))
        return interval

    def set_led(self, level: int) -> None:
        """Sets the LED: 0 off, 255 fully on, in between a PWM duty. Stops a blink."""
        if not 0 <= level <= 255:
            raise ConfigError(f"LED level must be 0..255, got {level}")
        self._request("RIG_CMD_LED", expects=("RIG_MSG_ACK",), fields={"level": level})

    def blink(self, *, bits: int, bit_s: float, seed: int, level: int = 255, start_in_s: float = 0.2) -> BlinkSchedule:
        """Plays `bits` bits of the blink code, starting `start_in_s` from now; returns the schedule."""
        spec = self.spec
        hz = spec["RIG_TICK_HZ"]
        bit_ticks = round(bit_s * hz)
        if not 1 <= bits <= spec["RIG_BLINK_MAX_BITS"]:
            raise ConfigError(f"bits must be 1..{spec['RIG_BLINK_MAX_BITS']}, got {bits}")
        if bit_ticks < spec["RIG_BLINK_MIN_BIT_TICKS"]:
            raise ConfigError(f"bit_s must be at least {spec['RIG_BLINK_MIN_BIT_TICKS'] / hz} s, got {bit_s}")
        if not 0 < seed < 1 << 16 or not 1 <= level <= 255:
            raise ConfigError(f"seed must be 1..65535 and level 1..255, got {seed} and {level}")
        if not 0.01 <= start_in_s <= 60:
            raise ConfigError(f"start_in_s must be 0.01..60 s, got {start_in_s}")
        start_tick = round((self.board_time_now() + start_in_s) * hz)
        fields = {"start_tick": start_tick % TickUnwrapper.WRAP, "bit_ticks": bit_ticks, "seed": seed, "bits": bits, "level": level}
        self._request("RIG_CMD_BLINK", expects=("RIG_MSG_ACK",), fields=fields)
        return BlinkSchedule(start_board_time=start_tick / hz, bit_s=bit_ticks / hz, seed=seed, bits=bits, level=level)

    def configure_encoder(self, report_hz: float = 0.0) -> None:
        """One report per edge (report_hz 0), or at most report_hz reports per second."""
        spec = self.spec
        hz = spec["RIG_TICK_HZ"]
        highest = hz / spec["RIG_ENCODER_MIN_REPORT_TICKS"]
        if report_hz != 0 and not 0 < report_hz <= highest:
            raise ConfigError(f"encoder report rate must be 0 (every edge) or up to {highest:g} Hz, got {report_hz}")
        self._configure("RIG_CMD_ENCODER", {"report_ticks": 0 if report_hz == 0 else round(hz / report_hz)})

    def configure_photodiode(self, rise: int, fall: int, raw_every: int = 0) -> None:
        """Crossings up through `rise` and down through `fall` (ADC counts, fall < rise), and every
        raw_every-th ADC sample (0: none)."""
        spec = self.spec
        top = spec["RIG_ADC_MAX"]
        if not 0 <= fall < rise <= top:
            raise ConfigError(f"photodiode thresholds need 0 <= fall < rise <= {top}, got rise {rise}, fall {fall}")
        if raw_every != 0 and raw_every < spec["RIG_SAMPLES_MIN_EVERY"]:
            raise ConfigError(f"raw_every must be 0 or at least {spec['RIG_SAMPLES_MIN_EVERY']}, got {raw_every}")
        self._configure("RIG_CMD_PHOTODIODE", {"rise": rise, "fall": fall, "raw_every": raw_every})

    def stream(self, *, encoder: bool = False, photodiode: bool = False, samples: bool = False) -> None:
        """Which event streams the board sends: encoder edges, photodiode crossings and passages,
        raw photodiode samples (LED changes always come)."""
        spec = self.spec
        mask = (
            (spec["RIG_STREAM_ENCODER"] if encoder else 0)
            | (spec["RIG_STREAM_PHOTODIODE"] if photodiode else 0)
            | (spec["RIG_STREAM_SAMPLES"] if samples else 0)
        )
        self._configure("RIG_CMD_STREAM", {"mask": mask})

    def _configure(self, command: str, fields: dict[str, int]) -> None:
        self._request(command, expects=("RIG_MSG_ACK",), fields=fields)
        self._config[command] = fields

    # ---- requests ----

    def _request(
        self, command: str, *, expects: tuple[str, ...], fields: dict[str, int] | None = None, tries: int | None = None
    ) -> _Answer:
        """Sends a command and waits for all its answers (or an ACK refusing it)."""
        spec = self.spec
        if not self._threads:
            raise RigError(f"the board at {self.url} is not connected")
        command_type = spec.type_id(command)
        payload = spec.layout(command_type).pack(**(fields or {}))
        attempts = self._tries if tries is None else tries
        for _ in range(attempts):
            self._wait_for_link()
            seq = next(self._seq) % 256
            pending = _Pending(expects=tuple(spec.type_id(name) for name in expects))
            with self._pending_lock:
                self._pending[seq] = pending
            try:
                sent = self._write(encode_frame(command_type, seq, payload, spec))
                if not pending.done.wait(self._reply_timeout) or pending.link_lost:
                    continue
            except _LinkDown:
                continue
            finally:
                with self._pending_lock:
                    self._pending.pop(seq, None)
            if pending.ack_status is not None and pending.ack_status != spec["RIG_STATUS_OK"]:
                raise RigError(f"the board refused {command}: {spec.status_name(pending.ack_status)}")
            return _Answer(spec, sent, pending.answers, pending.received)
        self.check()
        raise RigError(
            f"the board at {self.url} did not answer {command} ({attempts} tries, {self._reply_timeout} s each): "
            "check the port, the cable and that the board runs the rig firmware"
        )

    def _wait_for_link(self) -> None:
        """Returns once the port is open; raises if the link failed, closed or stayed down."""
        deadline = self._clock() + self._reconnect_timeout
        while not self._link_up.wait(READ_TIMEOUT_S):
            self.check()
            if self._stop.is_set():
                raise RigError(f"the connection to the board at {self.url} is closed")
            if self._clock() > deadline:
                raise RigError(f"the link to the board at {self.url} stayed down for {self._reconnect_timeout} s")
        self.check()
        if self._stop.is_set():
            raise RigError(f"the connection to the board at {self.url} is closed")

    def _write(self, frame: bytes) -> float:
        with self._port_lock:
            if self._port is None:
                raise _LinkDown()
            sent = self._clock()
            try:
                self._port.write(frame)
            except (serial.SerialException, OSError) as error:
                raise _LinkDown() from error
        return sent

    def _resolve(self, reply_to: int, message_type: int, fields: dict[str, Any], received: float) -> None:
        with self._pending_lock:
            pending = self._pending.get(reply_to)
            if pending is None or pending.done.is_set():
                return
            if message_type == self.spec["RIG_MSG_ACK"]:
                pending.ack_status = fields["status"]
            elif message_type not in pending.expects:
                return
            pending.answers[message_type] = fields
            pending.received[message_type] = received
            if pending.ack_status is not None or all(kind in pending.answers for kind in pending.expects):
                pending.done.set()

    def _fail_pending(self) -> None:
        with self._pending_lock:
            for pending in self._pending.values():
                pending.link_lost = True
                pending.done.set()

    # ---- reader thread ----

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            port = self._port
            if port is None:
                if not self._reconnect():
                    return
                continue
            try:
                data = port.read(max(1, port.in_waiting))
            except (serial.SerialException, OSError, TypeError) as error:
                # pyserial raises TypeError when close() takes the port away in the middle of a read.
                if not self._stop.is_set():
                    self._link_lost(str(error))
                continue
            if not data:
                continue
            received = self._clock()
            for frame in self._decoder.feed(data):
                self._dispatch(frame.type, self.spec.layout(frame.type).unpack(frame.payload), received)
            with self._listener_lock:
                for listener in self._listeners:
                    self._guard(listener.on_batch_end)

    def _link_lost(self, detail: str) -> None:
        with self._port_lock:
            port, self._port = self._port, None
            self._link_up.clear()
        if port is not None:
            _close_quietly(port)
        self._decoder.reset()
        self._fail_pending()
        self._emit(LinkChange(self._clock(), "lost", detail))

    def _reconnect(self) -> bool:
        """Reopens the port until it works (True), or until close() or the reconnect timeout (False)."""
        deadline = self._clock() + self._reconnect_timeout
        wait = RECONNECT_FIRST_WAIT_S
        while not self._stop.is_set():
            try:
                port = self._open()
            except RigError as error:
                if self._clock() >= deadline:
                    self._failure = RigError(
                        f"lost the board at {self.url} and could not reopen it within {self._reconnect_timeout} s: {error}"
                    )
                    self._emit(LinkChange(self._clock(), "failed", str(error)))
                    self._fail_pending()
                    return False
                self._stop.wait(wait)
                wait = min(2 * wait, RECONNECT_LONGEST_WAIT_S)
                continue
            with self._port_lock:
                if self._stop.is_set():
                    _close_quietly(port)
                    return False
                self._port = port
                self._link_up.set()
            self._reconnects += 1
            self._emit(LinkChange(self._clock(), "restored", self.url))
            self._restore_needed.set()
            return True
        return False

    def _dispatch(self, message_type: int, fields: dict[str, Any], received: float) -> None:
        spec = self.spec
        name = spec.type_names[message_type]
        if "reply_to" in fields and not fields.get("unsolicited"):
            self._resolve(fields["reply_to"], message_type, fields, received)
        if name == "RIG_MSG_STATUS":
            tick = self._unwrapper.anchor(fields["epoch"], fields["tick"])
            if fields["unsolicited"]:
                self._emit(self._status_event(fields, tick))
        elif name == "RIG_MSG_SYNC":
            self._unwrapper.anchor(fields["epoch"], fields["rx_tick"])
        elif name == "RIG_MSG_ENCODER":
            tick, board_time, rig_time = self._times(fields["tick"])
            self._emit(EncoderEdge(tick, board_time, rig_time, fields["count"], fields["step"], fields["edges"]))
        elif name == "RIG_MSG_CROSSING":
            tick, board_time, rig_time = self._times(fields["tick"])
            self._emit(PhotodiodeCrossing(tick, board_time, rig_time, bool(fields["rising"])))
        elif name == "RIG_MSG_PASSAGE":
            tick, board_time, rig_time = self._times(fields["centroid_tick"])
            start = tick - (fields["centroid_tick"] - fields["start_tick"]) % TickUnwrapper.WRAP
            end = tick + (fields["end_tick"] - fields["centroid_tick"]) % TickUnwrapper.WRAP
            self._emit(PhotodiodePassage(tick, board_time, rig_time, start, end, fields["peak"]))
        elif name == "RIG_MSG_SAMPLE":
            tick, board_time, rig_time = self._times(fields["tick"])
            self._emit(PhotodiodeSample(tick, board_time, rig_time, fields["value"]))
        elif name == "RIG_MSG_LED":
            tick, board_time, rig_time = self._times(fields["tick"])
            bit = None if fields["bit"] == spec["RIG_LED_MANUAL"] else fields["bit"]
            self._emit(LedChange(tick, board_time, rig_time, fields["level"], bit))

    def _times(self, tick32: int) -> tuple[int, float, float]:
        tick = self._unwrapper.unwrap(tick32)
        board_time = tick / self.spec["RIG_TICK_HZ"]
        return tick, board_time, self.to_rig_time(board_time)

    def _status_event(self, fields: dict[str, Any], tick: int) -> BoardStatus:
        counters = {name: fields[name] for name in BoardStatus.__dataclass_fields__ if name in fields}
        return BoardStatus(board_tick=tick, board_time=tick / self.spec["RIG_TICK_HZ"], **counters)

    def _emit(self, event: BoardEvent) -> None:
        with self._listener_lock:
            for listener in self._listeners:
                self._guard(lambda: listener.on_event(event))

    def _guard(self, call: Callable[[], None]) -> None:
        """Runs a listener call; a listener that cannot write stops the recording, not the thread."""
        try:
            call()
        except OSError as error:
            self._failure = RigError(f"could not record the board's events: {error}")

    # ---- keeper thread ----

    def _keep_loop(self) -> None:
        next_sync = self._next_sync_time()
        while not self._stop.is_set():
            wait = max(0.0, min(next_sync - self._clock(), 1.0))
            if self._restore_needed.wait(wait):
                self._restore_needed.clear()
                self._restore_with_retries()
                next_sync = self._next_sync_time()
            elif self._clock() >= next_sync:
                try:
                    self.sync()
                except RigError:
                    pass  # the link is down: the reconnection will synchronise
                next_sync = self._next_sync_time()

    def _next_sync_time(self) -> float:
        return self._clock() + self._resync_every if self._resync_every else math.inf

    def _restore_with_retries(self) -> None:
        for attempt in range(1, RESTORE_TRIES + 1):
            if self._stop.is_set() or self._restore_needed.is_set():
                return  # closing, or the link dropped again and the next reconnection restores
            try:
                self._restore()
                return
            except RigError as error:
                self._emit(LinkChange(self._clock(), "restore failed", f"try {attempt} of {RESTORE_TRIES}: {error}"))
                self._stop.wait(RESTORE_RETRY_S)
        self._failure = RigError(f"could not set the board at {self.url} up again after reconnecting; see link.csv")

    def _restore(self) -> None:
        """After a reconnection: identify and synchronise again, and resend the configuration in
        case the board was reset."""
        self.identify(tries=self._boot_tries)
        self.sync()
        for command, fields in list(self._config.items()):
            self._request(command, expects=("RIG_MSG_ACK",), fields=fields)
        self._emit(LinkChange(self._clock(), "configured", ", ".join(self._config)))


def _close_quietly(port: SerialPort) -> None:
    try:
        port.close()
    except (serial.SerialException, OSError):
        pass
