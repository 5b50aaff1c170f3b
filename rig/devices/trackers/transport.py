"""What moves a tracker's bytes: a transport opens the device and starts a reader, a thread that
waits for what the device sends, stamps each chunk with its arrival and queues it, nothing more.

A reader is compiled (`_readers.FdReader` for a port with a file descriptor, `_readers.LslReader`
for an LSL inlet: C threads that never wake the interpreter) or, where there is no compiled one
(HID, a port without a descriptor such as `loop://`), a `ThreadReader` in Python with the same
contract. Every reader stamps on the system's monotonic clock counted from an origin
(`monotonic_origin_ns`), so the stamps are on any rig clock's time line and every clock runs the
same readers. What the chunks mean is the decoder's business (`rig.devices.trackers.decoders`).
"""

from __future__ import annotations

import errno
import threading
import time
from typing import Any, Callable, Protocol

from rig.clock import Clock, MonotonicClock

NS_PER_S = 1_000_000_000


class Reader(Protocol):
    """A reader thread, running from when it is made: it queues what arrives, stamped on the rig
    clock, until the device's link ends or `stop()`."""

    outcome: str | None
    """None while it reads; then how it ended: "stopped", "end of file" or "error"."""
    errno: int
    """Where the outcome is "error", the failed call's code (errno; liblsl's, negative, for an inlet)."""
    cpu_s: float
    """The CPU time its thread has used, once it has ended."""

    def take(self) -> tuple[list[Any], list[float]]:
        """Every chunk queued since the last take, in order, and their arrival times."""

    def wait(self, timeout_s: float | None = None) -> bool:
        """True once there is a chunk to take or the reader has ended, False after `timeout_s`."""

    def wait_ended(self, timeout_s: float | None = None) -> bool:
        """True once the reader has ended, False after `timeout_s` (None: no limit)."""

    def stop(self) -> None:
        """Ends the reader and joins its thread; what it queued stays to be taken."""


class Transport(Protocol):
    """A device's link: `open` (RigError saying what to do if it cannot), `reader` to read the
    opened device, `upkeep` beside the reading (on the stream's supervising thread, never the
    consumer's: it may wait on the network), `close`."""

    description: str

    def open(self, origin_ns: int) -> None:
        """Opens the device; its stamps go on the time line of monotonic ns less `origin_ns`."""

    def reader(self) -> Reader:
        """A reader of the opened device, started."""

    def upkeep(self) -> None:
        """Called every fraction of a second while a reader reads (an LSL inlet measures its clock offset)."""

    def close(self) -> None: ...


def monotonic_origin_ns(clock: Clock) -> int:
    """The system's monotonic time (ns) at `clock`'s zero: exactly a MonotonicClock's origin where it
    is on the system clock, else measured now (a clock that runs at the system's rate, such as a
    test's own), so that a reader's stamps fall on `clock`'s time line."""
    if isinstance(clock, MonotonicClock) and clock.on_system_clock:
        return clock.origin_ns
    return time.monotonic_ns() - round(clock.now() * NS_PER_S)


class ThreadReader:
    """A reader thread in Python, for a transport without a compiled one. `receive()` waits briefly
    (tens of ms, so that the thread notices `stop`) and gives a chunk, None if nothing came, b"" at
    the end of the link, or raises OSError where reading failed (hidapi's and pyserial's errors)."""

    def __init__(self, receive: Callable[[], Any], origin_ns: int, name: str) -> None:
        self.outcome: str | None = None
        self.errno = 0
        self.cpu_s = 0.0
        self._receive = receive
        self._origin_ns = origin_ns
        self._chunks: list[Any] = []
        self._arrivals: list[float] = []
        self._changed = threading.Condition()
        self._stopping = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        started = time.thread_time()
        receive, now_ns, origin_ns, changed = self._receive, time.monotonic_ns, self._origin_ns, self._changed
        outcome, code = "error", errno.EIO  # unless the loop ends as it should
        try:
            while not self._stopping:
                chunk = receive()
                if chunk is None:
                    continue
                if not chunk:
                    outcome, code = "end of file", 0
                    break
                arrival = (now_ns() - origin_ns) / NS_PER_S
                with changed:
                    self._chunks.append(chunk)
                    self._arrivals.append(arrival)
                    changed.notify_all()
            else:
                outcome, code = "stopped", 0
        except OSError as error:
            outcome, code = "error", error.errno or errno.EIO
        finally:
            with changed:
                self.cpu_s = time.thread_time() - started
                self.outcome, self.errno = outcome, code
                changed.notify_all()

    def take(self) -> tuple[list[Any], list[float]]:
        with self._changed:
            taken = self._chunks, self._arrivals
            self._chunks, self._arrivals = [], []
        return taken

    def wait(self, timeout_s: float | None = None) -> bool:
        with self._changed:
            return self._changed.wait_for(lambda: bool(self._chunks) or self.outcome is not None, timeout_s)

    def wait_ended(self, timeout_s: float | None = None) -> bool:
        with self._changed:
            return self._changed.wait_for(lambda: self.outcome is not None, timeout_s)

    def stop(self) -> None:
        self._stopping = True
        self._thread.join()
