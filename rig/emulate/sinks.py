"""Where an emulated tracker sends its records: a pseudo-terminal, a TCP socket, or an LSL outlet.

Each sink waits for a reader before it streams (`wait_for_reader`), as a tracker told to start by
its host would, so a recording can hold every record sent. `disconnect` takes the port away (the
pty is destroyed, the socket and its listener closed, the outlet deleted) and `reconnect` brings
it back at the same address and waits for the reader to return.

A serial sink never queues records for a reader that does not take them: it writes through an
`Outbox` (outbox.py), which waits a bounded time for a slow reader and then sends no more until the
reader takes bytes again (the streamer logs those records `unread`), and never tears a record. Once its reader has hung up
(the pty's slave closed by everyone, the TCP client gone) `send` raises ReaderGone and the emulator
ends: nothing is written for a reader that has not connected.
"""

from __future__ import annotations

import os
import select
import socket
import time
import tty
from abc import ABC, abstractmethod
from pathlib import Path
from typing import Any, Callable, Sequence

from rig.devices.trackers.lsl_tracker import pose_outlet
from rig.emulate.encode import Emission, RecordEncoder
from rig.emulate.outbox import WRITE_WAIT_S, Outbox
from rig.emulate.streamer import ReaderGone
from rig.errors import RigError
from rig.sim.tracker_faults import ByteFaults

# After a reader opens the port it may flush what is waiting (pyserial does): start a little later.
READER_GRACE_S = 0.1
POLL_S = 0.02


class _ByteSink(ABC):
    """What a pty and a TCP sink share: records encoded as the profile says, their bytes damaged as the
    faults say, written through an `Outbox` with waits of at most `write_wait_s`."""

    def __init__(
        self, encoder: RecordEncoder, faults: ByteFaults, sleep: Callable[[float], None], write_wait_s: float
    ) -> None:
        self._encoder = encoder
        self._faults = faults
        self._sleep = sleep
        self._write_wait_s = write_wait_s
        self._outbox: Outbox | None = None

    @abstractmethod
    def _reader_gone(self) -> bool:
        """Whether the reader has gone (a pty's every slave closed, a TCP client disconnected)."""

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]:
        """Writes the records at once, as many as the port takes: (damaged per record written, the
        first ones of `emissions`; the monotonic time of the write). ReaderGone once the reader has gone."""
        if self._reader_gone():
            raise ReaderGone
        chunks, damaged = zip(*(self._faults.apply(self._encoder.encode(e), rate_hz) for e in emissions))
        written = time.monotonic()
        try:
            taken = self._outbox.send(chunks)  # type: ignore[union-attr]
        except OSError:  # reset or a broken pipe: the reader went between the check and the write
            raise ReaderGone from None
        return list(damaged[:taken]), written


class PtySink(_ByteSink):
    """A pseudo-terminal whose slave is reachable at `link` (a symlink kept pointing at the live one)."""

    def __init__(
        self, link: Path, encoder: RecordEncoder, faults: ByteFaults, *, sleep: Callable[[float], None] = time.sleep,
        write_wait_s: float = WRITE_WAIT_S,
    ) -> None:  # fmt: skip
        super().__init__(encoder, faults, sleep, write_wait_s)
        self.link = Path(link)
        self.address = str(self.link)
        self._master = -1
        self._terminal = ""
        self._open()

    def _open(self) -> None:
        master, slave = os.openpty()
        tty.setraw(slave)
        name = os.ttyname(slave)
        os.close(slave)
        os.set_blocking(master, False)
        try:
            self._link_to(name)
        except OSError as error:
            os.close(master)
            raise RigError(f"--pty {self.link}: {_why_not(error, self.link)}") from None
        self._master = master
        self._terminal = name
        self._outbox = Outbox(lambda data: os.write(master, data), self._writable, self._write_wait_s)

    def _link_to(self, terminal: str) -> None:
        """Point the link at `terminal`: made where nothing is the first time (never replacing a
        file of the user's), swapped in at once when the port comes back."""
        if not self._terminal:
            os.symlink(terminal, self.link)
            return
        staged = self.link.with_name(self.link.name + ".new")
        os.symlink(terminal, staged)
        os.replace(staged, self.link)

    def _our_link(self) -> bool:
        try:
            return os.readlink(self.link) == self._terminal
        except OSError:
            return False

    def _reader_gone(self) -> bool:
        """Whether nobody has the terminal open."""
        poller = select.poll()
        poller.register(self._master, select.POLLHUP)
        return any(event & select.POLLHUP for _, event in poller.poll(0))

    def _writable(self, timeout_s: float) -> bool:
        """Whether the terminal has room within `timeout_s`; ReaderGone if its reader hangs up meanwhile."""
        poller = select.poll()
        poller.register(self._master, select.POLLOUT | select.POLLHUP)
        events = [event for _, event in poller.poll(max(0, round(timeout_s * 1e3)))]
        if any(event & select.POLLHUP for event in events):
            raise ReaderGone
        return bool(events)

    def wait_for_reader(self, stop_at: float) -> bool:
        while self._reader_gone():
            if time.monotonic() >= stop_at:
                return False
            self._sleep(POLL_S)
        self._sleep(READER_GRACE_S)
        return True

    def linger(self, seconds: float) -> None:
        poller = select.poll()
        poller.register(self._master, select.POLLHUP)
        poller.poll(round(seconds * 1e3))

    def disconnect(self) -> None:
        os.close(self._master)
        self._master = -1

    def reconnect(self, stop_at: float) -> bool:
        self._open()
        return self.wait_for_reader(stop_at)

    def close(self) -> None:
        if self._master >= 0:
            os.close(self._master)
            self._master = -1
        if self._our_link():  # never what someone put there meanwhile
            self.link.unlink()


def _why_not(error: OSError, link: Path) -> str:
    """Why the link could not be made at `link`, and what to do."""
    if isinstance(error, FileExistsError):
        return "something already exists there; name a path where nothing is (the link is made there and removed at the end)"
    if not link.parent.is_dir():
        return f"the folder {link.parent} does not exist; name a path in an existing folder"
    return f"cannot make a link there ({error.strerror}); name a path in a folder you can write"


class TcpSink(_ByteSink):
    """A TCP server on 127.0.0.1 (port 0: any free one) that streams to one client at a time, through
    a send buffer of `send_buffer_bytes` (None: the system's, which grows to megabytes)."""

    def __init__(
        self, port: int, encoder: RecordEncoder, faults: ByteFaults, *, sleep: Callable[[float], None] = time.sleep,
        write_wait_s: float = WRITE_WAIT_S, send_buffer_bytes: int | None = None,
    ) -> None:  # fmt: skip
        super().__init__(encoder, faults, sleep, write_wait_s)
        self._send_buffer = send_buffer_bytes
        self._client: socket.socket | None = None
        self._listener = self._listen(port)
        self.port = self._listener.getsockname()[1]
        self.address = f"socket://127.0.0.1:{self.port}"

    @staticmethod
    def _listen(port: int) -> socket.socket:
        listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            listener.bind(("127.0.0.1", port))
        except OSError as error:
            listener.close()
            raise RigError(f"cannot listen on 127.0.0.1:{port}: {error.strerror}; choose another --tcp port") from None
        listener.listen(1)
        return listener

    def wait_for_reader(self, stop_at: float) -> bool:
        while time.monotonic() < stop_at:
            ready, _, _ = select.select([self._listener], [], [], POLL_S)
            if ready:
                client, _ = self._listener.accept()
                client.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                if self._send_buffer is not None:
                    client.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, self._send_buffer)
                client.setblocking(False)
                self._client = client
                self._outbox = Outbox(client.send, lambda timeout_s: bool(select.select([], [client], [], timeout_s)[1]),
                                      self._write_wait_s)  # fmt: skip
                self._sleep(READER_GRACE_S)
                return True
        return False

    def _reader_gone(self) -> bool:
        """Whether the client has closed its end: a reader sends nothing, so anything to read is its end."""
        client = self._client
        if client is None:
            return True
        if not select.select([client], [], [], 0)[0]:
            return False
        try:
            return client.recv(1, socket.MSG_PEEK) == b""
        except BlockingIOError:
            return False
        except OSError:
            return True

    def linger(self, seconds: float) -> None:
        if self._client is not None:
            select.select([self._client], [], [], seconds)  # readable once the client has closed its end

    def disconnect(self) -> None:
        for sock in (self._client, self._listener):
            if sock is not None:
                sock.close()
        self._client = None

    def reconnect(self, stop_at: float) -> bool:
        self._listener = self._listen(self.port)
        return self.wait_for_reader(stop_at)

    def close(self) -> None:
        self.disconnect()


class LslSink:
    """An LSL outlet of a 7-channel pose stream, stamped with the record's time on the LSL clock."""

    def __init__(self, name: str, rate_hz: float, source_id: str) -> None:
        self.name = name
        self.address = f"lsl:{name}"
        self._rate = rate_hz
        self._source_id = source_id
        self._outlet: Any = pose_outlet(name, rate_hz, source_id)

    def wait_for_reader(self, stop_at: float) -> bool:
        while time.monotonic() < stop_at:
            if self._outlet.wait_for_consumers(POLL_S):
                time.sleep(READER_GRACE_S)
                return True
        return False

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]:
        written = time.monotonic()
        for emission in emissions:
            self._outlet.push_sample([*emission.position, *emission.orientation], emission.device_time)
        return [False] * len(emissions), written

    def linger(self, seconds: float) -> None:
        time.sleep(seconds)  # an outlet does not say when its consumers have pulled what it holds

    def disconnect(self) -> None:
        self._outlet = None

    def reconnect(self, stop_at: float) -> bool:
        self._outlet = pose_outlet(self.name, self._rate, self._source_id)
        return self.wait_for_reader(stop_at)

    def close(self) -> None:
        self._outlet = None
