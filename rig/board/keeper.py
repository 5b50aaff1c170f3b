"""The keeper thread of a connected board: it synchronises the clocks again at a set interval
(which shows drift), and after a reconnection sets the board up again, trying a few times."""

from __future__ import annotations

import math
import threading
from typing import Callable

from rig.board.events import LinkChange
from rig.board.link import SerialLink
from rig.errors import RigError

# After a reconnection, setting the board up again is tried this often, this far apart.
RESTORE_TRIES = 5
RESTORE_RETRY_S = 0.5
# The longest the keeper sleeps before looking at the clock again.
LONGEST_SLEEP_S = 1.0


class Keeper:
    """Runs `sync` every `resync_every_s` (None: never) and `restore` after `request_restore()`, on
    the link's clock, until the link's `stop` is set.

    report: receives a LinkChange for each failed try at setting the board up again.
    fail: receives the error when every try failed; the connection is then unusable.
    """

    def __init__(
        self,
        link: SerialLink,
        *,
        resync_every_s: float | None,
        sync: Callable[[], object],
        restore: Callable[[], None],
        report: Callable[[LinkChange], None],
        fail: Callable[[RigError], None],
    ) -> None:
        self._link = link
        self._resync_every = resync_every_s
        self._sync = sync
        self._restore = restore
        self._report = report
        self._fail = fail
        self._restore_needed = threading.Event()

    def request_restore(self) -> None:
        """Sets the board up again as soon as possible (and wakes the keeper, to see `stop`)."""
        self._restore_needed.set()

    def run(self) -> None:
        """The keeper thread."""
        next_sync = self._next_sync_time()
        while not self._link.stop.is_set():
            wait = max(0.0, min(next_sync - self._link.clock(), LONGEST_SLEEP_S))
            if self._restore_needed.wait(wait):
                self._restore_needed.clear()
                self._restore_with_retries()
                next_sync = self._next_sync_time()
            elif self._link.clock() >= next_sync:
                try:
                    self._sync()
                except RigError:
                    pass  # the link is down: the reconnection will synchronise
                next_sync = self._next_sync_time()

    def _next_sync_time(self) -> float:
        return self._link.clock() + self._resync_every if self._resync_every else math.inf

    def _restore_with_retries(self) -> None:
        for attempt in range(1, RESTORE_TRIES + 1):
            if self._link.stop.is_set() or self._restore_needed.is_set():
                return  # closing, or the link dropped again and the next reconnection restores
            try:
                self._restore()
                return
            except RigError as error:
                detail = f"try {attempt} of {RESTORE_TRIES}: {error}"
                self._report(LinkChange(self._link.clock(), "restore failed", detail))
                self._link.stop.wait(RESTORE_RETRY_S)
        self._fail(RigError(f"could not set the board at {self._link.url} up again after reconnecting; see link.csv"))
