"""How a serial sink writes: never blocking for good on a reader that does not read, never queueing a
backlog for it, and never tearing a record.

The port is non-blocking. A write the port cannot take whole waits for room up to WRITE_WAIT_S (a
reader on a loaded machine may stall for seconds and then catch up: its records arrive late, none
lost); past that the reader is taken as not reading: records that found no room are not sent
(`unread`), and until the port takes bytes again later records are not waited for either, so the
emulator keeps its schedule and a reader that comes back receives only what was written after. A
record the port took in part keeps its rest, written before anything else once there is room: no
record reaches the reader torn (a torn line would spoil the whole one after it too).
"""

from __future__ import annotations

import time
from typing import Callable, Sequence

WRITE_WAIT_S = 5.0


class Outbox:
    """Writes records through `write` (bytes in, how many the port took; BlockingIOError when it took
    none), waiting for room with `writable(timeout_s) -> bool` (it may raise the sink's ReaderGone),
    at most `wait_s` a call, on the monotonic `clock`."""

    def __init__(
        self, write: Callable[[bytes], int], writable: Callable[[float], bool], wait_s: float = WRITE_WAIT_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:  # fmt: skip
        self._write = write
        self._writable = writable
        self._wait_s = wait_s
        self._clock = clock
        self._rest = b""
        self._stalled = False

    def _put(self, data: bytes, deadline: float) -> bytes:
        """Writes `data` as far as the port takes it by `deadline`; what is left."""
        while True:
            try:
                data = data[self._write(data) :]
            except BlockingIOError:
                pass
            if not data or self._clock() >= deadline or not self._writable(deadline - self._clock()):
                return data

    def send(self, chunks: Sequence[bytes]) -> int:
        """Writes `chunks` (one a record) in order while the port takes them in time: how many it took
        (the last of them perhaps in part, its rest kept for the next call); the rest are not sent."""
        deadline = self._clock() + (0.0 if self._stalled else self._wait_s)
        self._rest = self._put(self._rest, deadline) if self._rest else b""
        self._stalled = bool(self._rest)
        if self._stalled:
            return 0
        for taken, chunk in enumerate(chunks):
            rest = self._put(chunk, deadline) if chunk else b""
            if rest:
                self._stalled = True
                self._rest = rest if len(rest) < len(chunk) else b""  # kept only where part went
                return taken + bool(self._rest)
        return len(chunks)
