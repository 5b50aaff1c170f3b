"""The emulated tracker's sending loop: a record every 1 / rate seconds, faults on schedule, and a log
of what became of every record (`SENT_COLUMNS`), written as it goes.

A record's fate is `intact` (sent as encoded; garbage bytes before it leave it so), `damaged`
(sent with bytes changed or left out) or `lost` (measured while the port was away, never sent). `t_write` is the monotonic time (s, `time.monotonic`) just before the write, which
the tracker bench compares with the rig's arrival times.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable, Protocol, Sequence

from rig.emulate.encode import Emission
from rig.emulate.faults import FaultPlan
from rig.emulate.motion import Motion
from rig.records import CsvRecord

SENT_COLUMNS = ("seq", "device_time", "t_write", "fate")
# How long a sink waits for its reader to come (back) before the emulator gives up.
READER_TIMEOUT_S = 60.0
# Before a disconnect, and at the end, the emulator lets the reader take what is in flight.
DRAIN_S = 0.05


class Sink(Protocol):
    address: str

    def wait_for_reader(self, stop_at: float) -> bool: ...

    def send(self, emissions: Sequence[Emission], rate_hz: float) -> tuple[list[bool], float]: ...

    def connected(self) -> bool: ...

    def disconnect(self) -> None: ...

    def reconnect(self, stop_at: float) -> bool: ...

    def close(self) -> None: ...


@dataclass
class SentCounts:
    intact: int = 0
    damaged: int = 0
    lost: int = 0

    @property
    def sent(self) -> int:
        return self.intact + self.damaged


def stream(
    motion: Motion,
    sink: Sink,
    duration_s: float,
    plan: FaultPlan,
    device_clock: Callable[[float], float],
    log: CsvRecord | None,
    on_event: Callable[[str], None] = lambda message: None,
) -> SentCounts:
    """Sends duration_s * rate records through `sink` once a reader is there; `device_clock` turns a
    monotonic time into the device's own. Returns what was sent."""
    counts = SentCounts()
    rate = motion.rate_hz
    total = int(round(duration_s * rate))
    if not sink.wait_for_reader(time.monotonic() + READER_TIMEOUT_S):
        on_event("no reader came; nothing sent")
        return counts
    on_event(f"reader connected; sending {total} records at {rate:g} Hz")
    motion.pose(0)  # the first block of poses is worked out before the clock starts, not late
    start = time.monotonic()
    held: list[Emission] = []
    stalled = disconnected = False

    def record(emissions: Sequence[Emission], fates: Sequence[str], t_write: float) -> None:
        for emission, fate in zip(emissions, fates):
            setattr(counts, fate, getattr(counts, fate) + 1)
            if log is not None:
                log.write((emission.seq, emission.device_time, t_write, fate))
        if log is not None:
            log.flush()

    def flush() -> None:
        if held:
            damaged, t_write = sink.send(held, rate)
            record(held, ["damaged" if d else "intact" for d in damaged], t_write)
            held.clear()

    k = 0
    while k < total:
        t_k = start + k / rate
        delay = t_k - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        elapsed = t_k - start
        if plan.disconnect and not disconnected and elapsed >= plan.disconnect[0]:
            disconnected = True
            flush()
            time.sleep(DRAIN_S)
            sink.disconnect()
            on_event(f"disconnected at {elapsed:.3f} s for {plan.disconnect[1]:g} s")
            time.sleep(max(0.0, start + plan.disconnect[0] + plan.disconnect[1] - time.monotonic()))
            if not sink.reconnect(time.monotonic() + READER_TIMEOUT_S):
                on_event("the reader did not come back; stopping")
                break
            resumed = time.monotonic()
            on_event(f"reconnected at {resumed - start:.3f} s")
            while k < total and start + k / rate < resumed:
                t_lost = start + k / rate
                lost = Emission(k, device_clock(t_lost), *motion.pose(k))
                record([lost], ["lost"], t_lost)
                k += 1
            continue
        position, orientation, angular_rate = motion.pose(k)
        held.append(Emission(k, device_clock(t_k), position, orientation, angular_rate))
        in_stall = plan.stall is not None and plan.stall[0] <= elapsed < plan.stall[0] + plan.stall[1]
        if in_stall and not stalled:
            stalled = True
            on_event(f"stalling at {elapsed:.3f} s for {plan.stall[1]:g} s")
        if not in_stall and len(held) >= plan.burst:
            flush()
        k += 1
    flush()
    time.sleep(DRAIN_S)
    return counts
