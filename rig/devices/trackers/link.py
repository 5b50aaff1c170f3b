"""What a tracker stream reads: a device's link (its transport and decoder), the compiled reader
a link may offer, and the loss of a link. Serial, HID and LSL sources implement `Link`;
`rig.devices.trackers.stream.TrackerStream` reads any of them."""

from __future__ import annotations

from typing import Any, Protocol

from rig.clock import Clock
from rig.devices.trackers.readings import Readings


class LinkLost(Exception):
    """The device went away while reading (unplugged, the socket closed, the stream ended)."""


class NativeReader(Protocol):
    """A link's compiled reader (`_readers.FdReader`, `_readers.LslReader`), reading on a thread of
    its own from when it is made: it queues what arrives, stamped on the rig clock, until the link
    ends or `stop()`."""

    outcome: str | None
    """None while it reads; then how it ended: "stopped", "end of file" or "error"."""
    errno: int
    """Where the outcome is "error", the failed call's code (errno; liblsl's for an inlet)."""
    cpu_s: float
    """The CPU time its thread has used."""

    def take(self) -> tuple[list[Any], list[float]]:
        """Every chunk queued since the last take, in order, and their arrival times."""

    def wait(self, timeout_s: float | None = None) -> bool:
        """True once there is a chunk to take or the reader has ended, False after `timeout_s`."""

    def wait_ended(self, timeout_s: float | None = None) -> bool:
        """True once the reader has ended, False after `timeout_s` (None: no limit)."""

    def stop(self) -> None:
        """Ends the reader and joins its thread; what it queued stays to be taken."""


class Link(Protocol):
    """What a stream reads: a device's transport and its decoder. `receive` runs on the reader
    thread and waits briefly (tens of ms) so that the reader notices close; `decode` and `restart`
    run on the consumer's thread, in the order the chunks came."""

    description: str
    corrupt: int

    def open(self, clock: Clock) -> None:
        """Opens the device, its times to go on `clock`; RigError saying what to do if it cannot."""

    def native_reader(self, clock: Clock) -> NativeReader | None:
        """A compiled reader of the opened device, stamping on `clock`, or None where there is none
        (then the stream's thread reads with `receive`)."""

    def upkeep(self, clock: Clock) -> None:
        """Work beside the reading, on the reading side and never on the consumer's thread (it may
        wait on the network): an LSL inlet measures its clock offset. The stream's supervisor calls
        it every UPKEEP_INTERVAL_S while a compiled reader reads; a Python `receive` does its own."""

    def receive(self, clock: Clock) -> Any:
        """What arrived (None if nothing did in time); raises LinkLost when the device went away."""

    def decode(self, chunks: list[Any], arrivals: list[float]) -> Readings:
        """The readings that received chunks complete, in order, each stamped with the arrival of
        the chunk that completed it."""

    def restart(self) -> None:
        """Forgets a partial record: what follows comes from a reopened device."""

    def close(self) -> None: ...
