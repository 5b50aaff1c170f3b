"""The emulated tracker's sending loop: each record written when the simulated tracker says it reaches
the host (`rig.sim.tracker.TrackerSamples.t_arrival`, after its delay, jitter, bursts and stalls), a
disconnect acted out on the sink, and a log of what became of every record (`SENT_COLUMNS`), written
as it goes.

A record's fate is `intact` (sent as encoded; garbage bytes before it leave it so), `damaged`
(sent with bytes changed or left out), `lost` (dropped by the tracker, or due while the port was
away, never sent) or `unread` (not sent: the reader was not taking records and the port's buffer
was full; a sink queues nothing for a reader that does not read). `t_write` is the monotonic time (s, `time.monotonic`) just before the write (for
a lost record, when it was due), which the tracker bench compares with the rig's arrival times.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Protocol, Sequence

import numpy as np

from rig.emulate.encode import Emission
from rig.emulator_settings import ReaderWait
from rig.writers import CsvRecord
from rig.sim.tracker import TrackerSamples

SENT_COLUMNS = ("seq", "device_time", "t_write", "fate")
# How long after its last record the emulator waits for a reader to come back from a disconnect.
READER_RETURN_S = 2.0
# At the end the emulator keeps the port open up to this long for the reader to take what is in
# flight (less once the reader hangs up), as a closed pty loses what its reader has not read yet and
# a reader on a loaded machine may wait that long for the CPU; before a disconnect, up to half the
# time the port is away.
DRAIN_S = 1.0
DISCONNECT_DRAIN_S = 0.25


class ReaderGone(Exception):
    """Raised by a sink that cannot send once its reader has gone (a pty's writes would block)."""


class Sink(Protocol):
    address: str

    def wait_for_reader(self, stop_at: float) -> bool: ...

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]: ...

    def disconnect(self) -> None: ...

    def reconnect(self, stop_at: float) -> bool: ...

    def linger(self, seconds: float) -> None:
        """Keeps the port open up to `seconds` for the reader to take what is in flight, less once it hangs up."""

    def close(self) -> None: ...


@dataclass
class SentCounts:
    intact: int = 0
    damaged: int = 0
    lost: int = 0
    unread: int = 0

    @property
    def sent(self) -> int:
        return self.intact + self.damaged


def stream(
    samples: TrackerSamples,
    rates: np.ndarray,
    sink: Sink,
    rate_hz: float,
    disconnect: tuple[float, float] | None,
    device_clock: Callable[[float], float],
    log: CsvRecord | None,
    on_event: Callable[[str], None] = lambda message: None,
    on_start: Callable[[float], None] = lambda t: None,
    idle_timeout_s: float = ReaderWait.idle_timeout_s,
) -> SentCounts:
    """Sends `samples` (with their angular `rates`) through `sink` once a reader is there (given up
    after `idle_timeout_s` without one), until they are all sent or the reader hangs up;
    `device_clock` turns the monotonic time a sample was measured at into the device's own time,
    which its record carries; `disconnect` (when, for how long, in s from the start) is the one the
    fault plan holds, if any. Returns what was sent."""
    counts = SentCounts()
    if not sink.wait_for_reader(time.monotonic() + idle_timeout_s):
        on_event(f"no reader came in {idle_timeout_s:g} s; nothing sent")
        return counts
    on_event(f"reader connected; sending {int(np.count_nonzero(~samples.lost))} records at {rate_hz:g} Hz")
    seqs, due, lost = samples.seq.tolist(), samples.t_arrival.tolist(), samples.lost.tolist()
    measured, positions, orientations = samples.t_sensor.tolist(), samples.positions.tolist(), samples.orientations.tolist()
    angular_rates = rates.tolist()
    start = time.monotonic()
    on_start(start)

    def emission(k: int) -> Emission:
        return Emission(seqs[k], device_clock(start + measured[k]), tuple(positions[k]), tuple(orientations[k]), tuple(angular_rates[k]))

    def record(emissions: Sequence[Emission], fates: Sequence[str], t_write: float) -> None:
        for sent, fate in zip(emissions, fates):
            setattr(counts, fate, getattr(counts, fate) + 1)
            if log is not None:
                log.write((sent.seq, sent.device_time, t_write, fate))
        if log is not None:
            log.flush()

    away_until = -np.inf
    k, count = 0, len(seqs)
    while k < count:
        if disconnect is not None and due[k] >= disconnect[0]:
            time.sleep(min(DISCONNECT_DRAIN_S, disconnect[1] / 2))
            sink.disconnect()
            on_event(f"disconnected at {time.monotonic() - start:.3f} s for {disconnect[1]:g} s")
            time.sleep(max(0.0, start + sum(disconnect) - time.monotonic()))
            if not sink.reconnect(start + max(due) + READER_RETURN_S):
                on_event("the reader did not come back; stopping")
                break
            away_until, disconnect = time.monotonic() - start, None
            on_event(f"reconnected at {away_until:.3f} s")
            continue
        if lost[k] or due[k] < away_until:
            record([emission(k)], ["lost"], start + due[k])
            k += 1
            continue
        group = k + 1
        while group < count and due[group] == due[k] and not lost[group]:
            group += 1
        delay = start + due[k] - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        emissions = [emission(j) for j in range(k, group)]
        try:
            damaged, t_write = sink.send(emissions, rate_hz)
        except ReaderGone:
            on_event("the reader went away; stopping")
            return counts
        fates = ["damaged" if d else "intact" for d in damaged]
        record(emissions, fates + ["unread"] * (len(emissions) - len(fates)), t_write)
        k = group
    sink.linger(DRAIN_S)
    return counts
