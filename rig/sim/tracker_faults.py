"""The one fault model of the simulated tracker (`rig.sim.tracker`), from a spec such as
`corrupt=0.01,disconnect=4:0.5`:

    corrupt=P         each byte replaced by another with probability P (serial)
    drop=P            each byte left out with probability P (serial)
    garbage=R         R times a second on average, 1 to 32 random bytes between records (serial)
    burst=N           records sent N at a time, as a buffering USB bridge does
    stall=AT:S        at AT s nothing is sent for S s; then what was held goes at once
    disconnect=AT:S   at AT s the port (or LSL outlet) goes away for S s; records meanwhile are lost

Times are on the tracker's time line (the stream's start for `rig emulate-tracker`, the rig clock
in a simulated run). `delivered` applies the faults in time (burst, stall, disconnect) to when
records reach the host, for the in-process tracker and the emulator alike; `ByteFaults` damages the
bytes the emulator sends, so corrupt, drop and garbage exist only where there are bytes (a serial
stream). All randomness comes from one seeded generator, so a seed fixes every fault.
"""

from __future__ import annotations

import numpy as np

from rig.sim.fault_plan import FaultPlan

_GARBAGE_MAX = 32


def delivered(plan: FaultPlan, t_arrival: np.ndarray, lost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """When each record reaches the host under the plan's disconnect, stall and burst, and which are
    lost, from when each would arrive (in order) and which were lost already: a disconnect loses
    what would arrive while the link is away, a stall holds what would arrive during it until its
    end, and a burst holds records until the last of each N sent has come."""
    t, lost = t_arrival.copy(), lost.copy()
    if plan.disconnect:
        at, seconds = plan.disconnect
        lost |= (t >= at) & (t < at + seconds)
    if plan.stall:
        at, seconds = plan.stall
        t[(t >= at) & (t < at + seconds)] = at + seconds
    if plan.burst > 1:
        sent = np.flatnonzero(~lost)
        last_of_group = np.minimum((np.arange(sent.size) // plan.burst + 1) * plan.burst, sent.size) - 1
        t[sent] = t[sent[last_of_group]]
    return t, lost


class ByteFaults:
    """Damages records' bytes as the plan says: `apply(record, rate_hz)` gives (bytes to send, damaged)."""

    def __init__(self, plan: FaultPlan, seed: int) -> None:
        self.plan = plan
        self._rng = np.random.default_rng(seed)

    def apply(self, record: bytes, rate_hz: float) -> tuple[bytes, bool]:
        plan, rng = self.plan, self._rng
        prefix = b""
        if plan.garbage and rng.random() < plan.garbage / rate_hz:
            prefix = rng.integers(0, 256, int(rng.integers(1, _GARBAGE_MAX + 1)), dtype=np.uint8).tobytes()
        data = np.frombuffer(record, dtype=np.uint8).copy()
        damaged = False
        if plan.corrupt:
            hit = rng.random(data.size) < plan.corrupt
            if hit.any():
                data[hit] = (data[hit] + rng.integers(1, 256, int(hit.sum()))) % 256
                damaged = True
        if plan.drop:
            keep = rng.random(data.size) >= plan.drop
            if not keep.all():
                data = data[keep]
                damaged = True
        return prefix + data.tobytes(), damaged
