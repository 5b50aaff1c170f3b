"""The rig's microcontroller, over a serial link: identity, clock sync, LED, encoder and photodiode.

`Microcontroller(url)` only remembers where the board is; `connect()` (or `with`) opens the port
through `serial.serial_for_url` (a /dev/tty... path, the emulated board's pty, `loop://`, or any
opener passed in), starts a reader thread that decodes frames as they arrive, asks the board who it
is and synchronises the clocks. Every event goes to the listeners as it arrives, with its board
time converted to the rig clock. If the link drops, the reader reopens the port, and a keeper
thread synchronises again and restores the board's configuration; nothing received before is lost.

The parts: the line and its reader (link.py), commands and their answers (requests.py), messages
as events (messages.py), the keeper thread (keeper.py); this module holds the commands themselves.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import asdict
from typing import Callable, Protocol

from analysis.board.blink_code import BlinkSchedule
from rig.board.clock_sync import ClockModel, OffsetInterval, RoundTrip, TickUnwrapper, narrow
from rig.board.events import BoardEvent, BoardIdentity, BoardStatus, ClockSynced, LinkChange
from rig.board.framing import Frame, encode_frame
from rig.board.keeper import Keeper
from rig.board.link import SerialLink, SerialPort, open_serial_url
from rig.board.messages import MessageReader, status_event
from rig.board.protocol import protocol
from rig.board.requests import Answer, Requests
from rig.errors import ConfigError, RigError


class BoardListener(Protocol):
    """Receives the board's events on the reader thread; on_batch_end follows each batch of
    events that arrived together (the moment to flush a file)."""

    def on_event(self, event: BoardEvent) -> None: ...

    def on_batch_end(self) -> None: ...


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
        self._clock = clock
        self._tries = tries
        self._boot_tries = max(tries, math.ceil(boot_s / reply_timeout_s))
        self._sync_round_trips = sync_round_trips
        self._resync_every = resync_every_s
        self._stop = threading.Event()
        self._failure: RigError | None = None
        self._config: dict[str, dict[str, int]] = {}
        self.identity: BoardIdentity | None = None
        self.clock_model = ClockModel()
        self._clock_lock = threading.Lock()
        self._listeners: list[BoardListener] = []
        self._listener_lock = threading.RLock()
        self._threads: list[threading.Thread] = []
        self._link = SerialLink(
            url,
            open_port=open_port,
            clock=clock,
            reconnect_timeout_s=reconnect_timeout_s,
            stop=self._stop,
            on_frames=self._on_frames,
            on_change=self._on_link_change,
        )
        self._requests = Requests(self._link, reply_timeout_s=reply_timeout_s, check=self.check)
        self._messages = MessageReader(self.to_rig_time)
        self._keeper: Keeper | None = None

    # ---- connection ----

    def connect(self) -> BoardIdentity:
        """Opens the port, identifies the board and synchronises the clocks."""
        if self._threads:
            raise RigError(f"already connected to {self.url}")
        self._stop.clear()
        self._failure = None
        self._keeper = Keeper(
            self._link,
            resync_every_s=self._resync_every,
            sync=self.sync,
            restore=self._restore,
            report=self._emit,
            fail=self._fail,
        )
        self._link.open()
        self._start_thread(self._link.read_loop, "board-reader")
        try:
            identity = self.identify(tries=self._boot_tries)
            self.sync()
        except BaseException:
            self.close()
            raise
        self._start_thread(self._keeper.run, "board-keeper")
        return identity

    def close(self) -> None:
        """Stops the threads and closes the port; safe to call more than once."""
        self._stop.set()
        if self._keeper is not None:
            self._keeper.request_restore()  # wakes the keeper, which then sees the stop
        self._link.close()
        self._requests.fail_all()
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

    # ---- state ----

    @property
    def counters(self) -> dict[str, int]:
        """The host's link counters (see LinkCounters) and the number of reconnections."""
        return asdict(self._link.counters) | {"reconnects": self._link.reconnects}

    def to_rig_time(self, board_time: float) -> float:
        """The rig time of a board time (NaN before the first clock synchronisation)."""
        with self._clock_lock:
            if self.clock_model.latest is None:
                return math.nan
            return self.clock_model.to_rig_time(board_time)

    def board_time_now(self) -> float:
        """The board's time now, from the rig clock and the latest offset."""
        with self._clock_lock:
            latest = self.clock_model.latest
            if latest is None:
                raise RigError("the board clock is not synchronised yet")
            now = self._clock()
            return now + self.clock_model.offset_at(now)

    def check(self) -> None:
        """Raises the error that stopped the link (the port could not be reopened, or a listener
        could not write), if any."""
        for failure in (self._link.failure, self._failure):
            if failure is not None:
                raise failure

    def add_listener(self, listener: BoardListener) -> None:
        with self._listener_lock:
            self._listeners.append(listener)

    # ---- commands ----

    def identify(self, tries: int | None = None) -> BoardIdentity:
        answer = self._request("RIG_CMD_IDENTIFY", expects=("RIG_MSG_IDENTITY",), tries=tries)
        fields = answer.answer("RIG_MSG_IDENTITY")
        spec = protocol()
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
        self.identity = identity
        return identity

    def status(self) -> BoardStatus:
        fields = self._request("RIG_CMD_STATUS", expects=("RIG_MSG_STATUS",)).answer("RIG_MSG_STATUS")
        return status_event(fields, (fields["epoch"] << 32) | fields["tick"])

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
        spec = protocol()
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
            self.clock_model.add(interval)
        self._emit(ClockSynced(self._clock(), interval.low, interval.high, interval.round_trips, left_out))
        return interval

    def set_led(self, level: int) -> None:
        """Sets the LED: 0 off, 255 fully on, in between a PWM duty. Stops a blink."""
        if not 0 <= level <= 255:
            raise ConfigError(f"LED level must be 0..255, got {level}")
        self._request("RIG_CMD_LED", expects=("RIG_MSG_ACK",), fields={"level": level})

    def blink(self, *, bits: int, bit_s: float, seed: int, level: int = 255, start_in_s: float = 0.2) -> BlinkSchedule:
        """Plays `bits` bits of the blink code, starting `start_in_s` from now; returns the schedule."""
        spec = protocol()
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
        spec = protocol()
        hz = spec["RIG_TICK_HZ"]
        highest = hz / spec["RIG_ENCODER_MIN_REPORT_TICKS"]
        if report_hz != 0 and not 0 < report_hz <= highest:
            raise ConfigError(f"encoder report rate must be 0 (every edge) or up to {highest:g} Hz, got {report_hz}")
        self._configure("RIG_CMD_ENCODER", {"report_ticks": 0 if report_hz == 0 else round(hz / report_hz)})

    def configure_photodiode(self, rise: int, fall: int, raw_every: int = 0) -> None:
        """Crossings up through `rise` and down through `fall` (ADC counts, fall < rise), and every
        raw_every-th ADC sample (0: none)."""
        spec = protocol()
        top = spec["RIG_ADC_MAX"]
        if not 0 <= fall < rise <= top:
            raise ConfigError(f"photodiode thresholds need 0 <= fall < rise <= {top}, got rise {rise}, fall {fall}")
        if raw_every != 0 and raw_every < spec["RIG_SAMPLES_MIN_EVERY"]:
            raise ConfigError(f"raw_every must be 0 or at least {spec['RIG_SAMPLES_MIN_EVERY']}, got {raw_every}")
        self._configure("RIG_CMD_PHOTODIODE", {"rise": rise, "fall": fall, "raw_every": raw_every})

    def stream(self, *, encoder: bool = False, photodiode: bool = False, samples: bool = False) -> None:
        """Which event streams the board sends: encoder edges, photodiode crossings and passages,
        raw photodiode samples (LED changes always come)."""
        spec = protocol()
        mask = (
            (spec["RIG_STREAM_ENCODER"] if encoder else 0)
            | (spec["RIG_STREAM_PHOTODIODE"] if photodiode else 0)
            | (spec["RIG_STREAM_SAMPLES"] if samples else 0)
        )
        self._configure("RIG_CMD_STREAM", {"mask": mask})

    def _configure(self, command: str, fields: dict[str, int]) -> None:
        self._request(command, expects=("RIG_MSG_ACK",), fields=fields)
        self._config[command] = fields

    def _request(
        self, command: str, *, expects: tuple[str, ...], fields: dict[str, int] | None = None, tries: int | None = None
    ) -> Answer:
        if not self._threads:
            raise RigError(f"the board at {self.url} is not connected")
        return self._requests.send(command, expects=expects, fields=fields, tries=self._tries if tries is None else tries)

    def _restore(self) -> None:
        """After a reconnection: identify and synchronise again, and resend the configuration in
        case the board was reset."""
        self.identify(tries=self._boot_tries)
        self.sync()
        for command, fields in list(self._config.items()):
            self._request(command, expects=("RIG_MSG_ACK",), fields=fields)
        self._emit(LinkChange(self._clock(), "configured", ", ".join(self._config)))

    # ---- what the reader thread reports ----

    def _on_frames(self, frames: list[Frame], received: float) -> None:
        spec = protocol()
        for frame in frames:
            fields = spec.layout(frame.type).unpack(frame.payload)
            if "reply_to" in fields and not fields.get("unsolicited"):
                self._requests.resolve(fields["reply_to"], frame.type, fields, received)
            event = self._messages.event(frame.type, fields)
            if event is not None:
                self._emit(event)
        with self._listener_lock:
            for listener in self._listeners:
                self._guard(listener.on_batch_end)

    def _on_link_change(self, change: LinkChange) -> None:
        if change.kind in ("lost", "failed"):
            self._requests.fail_all()
        self._emit(change)
        if change.kind == "restored" and self._keeper is not None:
            self._keeper.request_restore()

    def _emit(self, event: BoardEvent) -> None:
        with self._listener_lock:
            for listener in self._listeners:
                self._guard(lambda: listener.on_event(event))

    def _guard(self, call: Callable[[], None]) -> None:
        """Runs a listener call; a listener that cannot write stops the recording, not the thread."""
        try:
            call()
        except OSError as error:
            self._fail(RigError(f"could not record the board's events: {error}"))

    def _fail(self, error: RigError) -> None:
        self._failure = error
