"""The serial line to the board: a port opened from a URL, a reader thread that decodes frames as
they arrive, and reopening the port when it drops.

The port is opened through `serial.serial_for_url` by default (a /dev/tty... path, the emulated
board's pty, `loop://`), or by any opener passed in. The link knows frames and ports, not what the
frames mean: it hands each batch of frames to `on_frames`, and tells `on_change` when the line is
lost, restored or given up.
"""

from __future__ import annotations

import threading
from typing import Callable, Protocol

import serial

from rig.board.events import LinkChange
from rig.board.framing import Frame, FrameDecoder, LinkCounters
from rig.board.protocol import protocol
from rig.errors import RigError

# How long one read waits for bytes, so that the reader notices close() promptly.
READ_TIMEOUT_S = 0.05
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


def open_serial_url(url: str) -> SerialPort:
    """The default opener: pyserial's serial_for_url at the protocol's baud rate."""
    return serial.serial_for_url(url, baudrate=protocol()["RIG_BAUD"], timeout=READ_TIMEOUT_S, write_timeout=1.0)


class LinkDown(Exception):
    """The port is closed or failed while writing; the reader thread is reconnecting."""


class SerialLink:
    """The port behind `url`, kept open by a reader thread (`read_loop`) until `stop` is set.

    on_frames(frames, received): the frames decoded from one read (maybe none, when the bytes held
        only part of a frame) and the rig time the bytes arrived; called on the reader thread.
    on_change(change): the line was lost, restored or given up ("failed"; `failure` then says why).
    reconnect_timeout_s: how long to keep trying to reopen a dropped port before giving up.
    """

    def __init__(
        self,
        url: str,
        *,
        open_port: Callable[[str], SerialPort],
        clock: Callable[[], float],
        reconnect_timeout_s: float,
        stop: threading.Event,
        on_frames: Callable[[list[Frame], float], None],
        on_change: Callable[[LinkChange], None],
    ) -> None:
        self.url = url
        self._open_port = open_port
        self.clock = clock
        self.reconnect_timeout_s = reconnect_timeout_s
        self.stop = stop
        self._on_frames = on_frames
        self._on_change = on_change
        self._port: SerialPort | None = None
        self._port_lock = threading.Lock()
        self._decoder: FrameDecoder | None = None
        self.up = threading.Event()
        self.failure: RigError | None = None
        self.reconnects = 0

    @property
    def counters(self) -> LinkCounters:
        """What the decoder saw on the line since the link was opened."""
        return self._decoder.counters if self._decoder else LinkCounters()

    def open(self) -> None:
        """Opens the port for a new connection, with fresh counters; raises RigError if it cannot."""
        self._decoder = FrameDecoder(protocol())
        self.failure = None
        self._port = self._open()
        self.up.set()

    def close(self) -> None:
        """Closes the port; the reader thread ends once `stop` is set."""
        with self._port_lock:
            port, self._port = self._port, None
            self.up.clear()
        if port is not None:
            _close_quietly(port)

    def write(self, frame: bytes) -> float:
        """Writes a frame; returns the rig time just before it went out. Raises LinkDown."""
        with self._port_lock:
            if self._port is None:
                raise LinkDown()
            sent = self.clock()
            try:
                self._port.write(frame)
            except (serial.SerialException, OSError) as error:
                raise LinkDown() from error
        return sent

    def _open(self) -> SerialPort:
        try:
            port = self._open_port(self.url)
            port.reset_input_buffer()
        except (serial.SerialException, OSError, ValueError) as error:
            raise RigError(f"cannot open the board's serial port {self.url}: {error}; check the cable and --port") from None
        return port

    def read_loop(self) -> None:
        """The reader thread: reads, decodes and hands on frames; reopens a dropped port."""
        while not self.stop.is_set():
            port = self._port
            if port is None:
                if not self._reconnect():
                    return
                continue
            try:
                data = port.read(max(1, port.in_waiting))
            except (serial.SerialException, OSError, TypeError, AttributeError) as error:
                # pyserial raises TypeError (AttributeError for socket://) when close() takes the port
                # away in the middle of a read.
                if not self.stop.is_set():
                    self._lost(str(error))
                continue
            if data:
                received = self.clock()
                self._on_frames(self._decoder.feed(data), received)

    def _lost(self, detail: str) -> None:
        self.close()
        self._decoder.reset()
        self._on_change(LinkChange(self.clock(), "lost", detail))

    def _reconnect(self) -> bool:
        """Reopens the port until it works (True), or until stop or the reconnect timeout (False)."""
        deadline = self.clock() + self.reconnect_timeout_s
        wait = RECONNECT_FIRST_WAIT_S
        while not self.stop.is_set():
            try:
                port = self._open()
            except RigError as error:
                if self.clock() >= deadline:
                    self.failure = RigError(
                        f"lost the board at {self.url} and could not reopen it within {self.reconnect_timeout_s} s: "
                        f"{error}"
                    )
                    self._on_change(LinkChange(self.clock(), "failed", str(error)))
                    return False
                self.stop.wait(wait)
                wait = min(2 * wait, RECONNECT_LONGEST_WAIT_S)
                continue
            with self._port_lock:
                if self.stop.is_set():
                    _close_quietly(port)
                    return False
                self._port = port
                self.up.set()
            self.reconnects += 1
            self._on_change(LinkChange(self.clock(), "restored", self.url))
            return True
        return False


def _close_quietly(port: SerialPort) -> None:
    try:
        port.close()
    except (serial.SerialException, OSError):
        pass
