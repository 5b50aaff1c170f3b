"""Host and board clocks reconciled as an interval of possible offsets (after google/walt).

One round trip: the host notes its time `sent` just before writing a request; the board notes its
time `board_rx` when the request's last byte arrived, answers, and notes `board_tx` when the last
byte of its answer went into its UART (reported in a second message); the host notes `received`
once that answer is in. With offset = board time - rig time,

    board_rx - offset >= sent + request_bytes * byte_time      the request cannot arrive sooner
    board_tx - offset <= received                              nor the answer before it is sent

so the offset lies in [board_tx - received, board_rx - sent - request_bytes byte_time]: bounds,
not estimates, whatever the delays of the USB-serial bridge, the operating system or the
emulator. Intersecting many round trips narrows the interval; measuring again later shows drift.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from analysis.board.intervals import consistent_intersection

# Offsets measured this far apart (rig seconds) give a drift rate; closer ones only noise.
MIN_DRIFT_BASELINE_S = 1.0
# A new interval this far from the offset predicted for it means the board clock restarted.
CLOCK_RESTART_S = 0.01


@dataclass(frozen=True)
class OffsetInterval:
    """Board time minus rig time, in seconds, known to lie in [low, high] around rig time `at`."""

    low: float
    high: float
    at: float
    round_trips: int = 1

    @property
    def width(self) -> float:
        return self.high - self.low

    @property
    def midpoint(self) -> float:
        return 0.5 * (self.low + self.high)


@dataclass(frozen=True)
class RoundTrip:
    """One request and reply, in rig seconds (sent, received) and board seconds (board_rx, board_tx)."""

    sent: float
    received: float
    board_rx: float
    board_tx: float

    def bounds(self, request_bytes: int, byte_time: float) -> OffsetInterval:
        """The offsets this round trip allows (see the module docstring)."""
        high = self.board_rx - self.sent - request_bytes * byte_time
        low = self.board_tx - self.received
        return OffsetInterval(low, high, 0.5 * (self.sent + self.received))


def narrow(intervals: Sequence[OffsetInterval]) -> tuple[OffsetInterval, int]:
    """Intersects the round trips of one measurement (a fraction of a second, over which the
    offset cannot move by more than a microsecond): returns the intersection of the largest set
    that agrees (see consistent_intersection) and how many round trips were left out. Raises
    ValueError when every interval is empty: the round trips contradict the byte times."""
    low, high, members = consistent_intersection([i.low for i in intervals], [i.high for i in intervals])
    at = float(np.mean([intervals[i].at for i in members]))
    return OffsetInterval(low, high, at, len(members)), len(intervals) - len(members)


@dataclass(frozen=True)
class Drift:
    """How fast the offset changes: board seconds gained per rig second (1e-6 is 1 ppm)."""

    rate: float
    uncertainty: float
    baseline_s: float


class ClockModel:
    """Converts board time to rig time from the offset intervals measured so far.

    Between two measurements the offset is interpolated linearly; after the latest it is
    extrapolated with the drift measured over the current run of the board's clock. Intervals are
    added in time order (`at` never decreasing). A measurement far from its prediction means the
    board's clock restarted (a reset): earlier measurements no longer apply and a new run starts.
    """

    def __init__(self) -> None:
        self._history: list[OffsetInterval] = []
        self._run: list[OffsetInterval] = []
        self._run_at: list[float] = []
        self._drift: Drift | None = None

    @property
    def intervals(self) -> tuple[OffsetInterval, ...]:
        """Every interval added, oldest first."""
        return tuple(self._history)

    @property
    def latest(self) -> OffsetInterval | None:
        return self._run[-1] if self._run else None

    def add(self, interval: OffsetInterval) -> None:
        if self._run and abs(interval.midpoint - self.offset_at(interval.at)) > CLOCK_RESTART_S:
            self._run = []
            self._run_at = []
        self._history.append(interval)
        self._run.append(interval)
        self._run_at.append(interval.at)
        self._drift = self._measure_drift()

    def drift(self) -> Drift | None:
        """Drift over the current run, once its measurements span MIN_DRIFT_BASELINE_S."""
        return self._drift

    def _measure_drift(self) -> Drift | None:
        if len(self._run) < 2:
            return None
        first, last = self._run[0], self._run[-1]
        baseline = last.at - first.at
        if baseline < MIN_DRIFT_BASELINE_S:
            return None
        rate = (last.midpoint - first.midpoint) / baseline
        return Drift(rate=rate, uncertainty=0.5 * (first.width + last.width) / baseline, baseline_s=baseline)

    def offset_at(self, rig_time: float) -> float:
        """The best offset for an event at `rig_time`."""
        if not self._run:
            raise ValueError("the clock has not been synchronised")
        run = self._run
        after = bisect.bisect_left(self._run_at, rig_time)
        if 0 < after < len(run):
            before, after = run[after - 1], run[after]
            fraction = (rig_time - before.at) / (after.at - before.at)
            return before.midpoint + fraction * (after.midpoint - before.midpoint)
        drift = self.drift()
        anchor = run[-1] if rig_time > run[-1].at else run[0]
        return anchor.midpoint + (drift.rate * (rig_time - anchor.at) if drift else 0.0)

    def offsets_at(self, rig_times: Sequence[float]) -> list[float]:
        """`offset_at` of each of `rig_times`, the same numbers; the extrapolation past the latest
        measurement, where a stream's new events fall, is set up once for all of them."""
        latest = self.latest
        if latest is None:
            raise ValueError("the clock has not been synchronised")
        midpoint, at = latest.midpoint, latest.at
        rate = self._drift.rate if self._drift else 0.0
        return [midpoint + rate * (t - at) if t > at else self.offset_at(t) for t in rig_times]

    def to_rig_time(self, board_time: float) -> float:
        """The rig time of a board time: solves rig = board - offset(rig) (two steps suffice, the
        offset changing by parts per million)."""
        return self.to_rig_times([board_time])[0]

    def to_rig_times(self, board_times: Sequence[float]) -> list[float]:
        """`to_rig_time` of each of `board_times`."""
        latest = self.latest
        if latest is None:
            raise ValueError("the clock has not been synchronised")
        rig_times = [board_time - latest.midpoint for board_time in board_times]
        for _ in range(2):
            rig_times = [board_time - offset for board_time, offset in zip(board_times, self.offsets_at(rig_times))]
        return rig_times


class TickUnwrapper:
    """Places a wrapping counter's ticks on a time line that does not wrap, using the latest tick as
    the reference for the next (no two ticks may be half a wrap apart). The board's 32-bit ticks
    (the default) also take full times from SYNC and STATUS messages as anchors; a tracker's
    16- or 32-bit timestamps and record counters are unwrapped with their own width.
    """

    WRAP = 1 << 32

    def __init__(self, bits: int = 32) -> None:
        self.wrap = 1 << bits
        self._reference: int | None = None

    def reset(self) -> None:
        self._reference = None

    def anchor(self, epoch: int, tick: int) -> int:
        self._reference = epoch * self.wrap + tick
        return self._reference

    def unwrap(self, tick: int) -> int:
        if self._reference is None:
            self._reference = tick
            return tick
        wrap = self.wrap
        full = self._reference - self._reference % wrap + tick
        if full - self._reference > wrap // 2:
            full -= wrap
        elif self._reference - full > wrap // 2:
            full += wrap
        self._reference = full
        return full

    def unwrap_many(self, ticks: Sequence[int]) -> list[int]:
        """`unwrap` of each of `ticks` in turn, the same numbers; where they lie in one wrap, within half
        a wrap of each other and of the reference (a stream's batch, but for the rare one that
        wraps), in one step for all."""
        reference = self._reference
        if reference is None or not ticks:
            return [self.unwrap(tick) for tick in ticks]
        wrap = self.wrap
        low, high = min(ticks), max(ticks)
        place = reference % wrap
        if low < 0 or high >= wrap or max(high, place) - min(low, place) > wrap // 2:
            return [self.unwrap(tick) for tick in ticks]
        base = reference - place
        fulls = [base + tick for tick in ticks] if base else list(ticks)
        self._reference = fulls[-1]
        return fulls
