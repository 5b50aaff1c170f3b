"""Ctrl-C and SIGTERM as KeyboardInterrupt, raised again where a library swallowed it.

Python raises KeyboardInterrupt wherever the main thread happens to be. Where that is inside a
garbage-collector callback (JAX registers one that runs during XLA's work), Python prints
"Exception ignored" and drops it, and a bare `except:` in a library drops it silently: the command
would run on to its end and exit 0. So the interrupt is also remembered until the command line has
handled it, and `raise_pending` (called by the progress bars, which long work calls while it works,
never while it cleans up) raises it again.

Inside `deferred()` an interrupt is only remembered, and raised when the section ends: for work
that runs Python code from native code, where a KeyboardInterrupt escapes as a C++ exception and
aborts the process (importing jaxlib's extensions does that).
"""

from __future__ import annotations

import signal
import sys
from contextlib import contextmanager
from types import FrameType
from typing import Iterator

_pending: type[KeyboardInterrupt] | None = None
_deferring = 0


class Terminated(KeyboardInterrupt):
    """SIGTERM, handled as an interrupt: the command stops, keeping what it recorded."""


def _interrupt(signum: int, frame: FrameType | None) -> None:
    global _pending
    _pending = Terminated if signum == signal.SIGTERM else KeyboardInterrupt
    if not _deferring:
        raise _pending()


def _unraisable(unraisable: sys.UnraisableHookArgs) -> None:
    """Python's report of an exception it had to drop, except an interrupt: that one is remembered
    and raised again, so its "Exception ignored" traceback would only alarm the user."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt):
        return
    sys.__unraisablehook__(unraisable)


def install() -> None:
    """Handle SIGINT and SIGTERM in this process (the main thread) from now on."""
    signal.signal(signal.SIGINT, _interrupt)
    signal.signal(signal.SIGTERM, _interrupt)
    sys.unraisablehook = _unraisable


def pending() -> type[KeyboardInterrupt] | None:
    """The interrupt asked for and not yet handled, if any."""
    return _pending


def raise_pending() -> None:
    """Raise the interrupt asked for again, if something swallowed it."""
    if _pending is not None:
        raise _pending()


def handled() -> None:
    """The command line has stopped the command: nothing is pending any more."""
    global _pending
    _pending = None


@contextmanager
def deferred() -> Iterator[None]:
    """A section an interrupt does not break into: one that comes meanwhile is raised at its end."""
    global _deferring
    _deferring += 1
    try:
        yield
    finally:
        _deferring -= 1
    if not _deferring:
        raise_pending()
