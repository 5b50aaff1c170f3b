"""What a tracker source counts while it reads, reported at the end of every run.

* received: samples handed on (intact, possible, in or out of order);
* corrupt: records that arrived damaged (a failed check, a field that does not parse, a malformed
  report) and were discarded; a binary stream's damaged stretch counts as many records as its
  length holds;
* rejected: intact records with impossible values (not finite, a quaternion not of unit norm),
  discarded and logged;
* dropped: records the device numbered that never arrived at all (gaps in its counter not taken
  up by corrupt or rejected ones), known only for profiles with a `seq` field;
* out_of_order: samples whose device time (or counter) is not after their predecessor's;
* reconnects: times the link was lost and restored.
"""

from __future__ import annotations

from array import array
from dataclasses import dataclass
from operator import lt
from typing import Any, Iterable

import numpy as np

from rig.board.clock_sync import TickUnwrapper
from rig.devices.trackers.readings import Readings

# Latency histogram: 10 us bins up to 2 s; later ones count in the last bin.
_BIN_S = 1e-5
_BINS = 200_000


@dataclass
class TrackerCounters:
    received: int = 0
    corrupt: int = 0
    rejected: int = 0
    dropped: int | None = None
    out_of_order: int = 0
    reconnects: int = 0


class SequenceCheck:
    """Counts dropped and out-of-order records from a record counter of `bits` bits, or from device
    times where there is none (out-of-order only)."""

    def __init__(self, counters: TrackerCounters, bits: int | None) -> None:
        self._counters = counters
        self._unwrap = TickUnwrapper(bits) if bits else None
        if bits:
            counters.dropped = 0
        self._last_seq: int | None = None
        self._last_time: float | None = None
        self._discarded_since = 0
        self._restored = False

    def link_restored(self) -> None:
        """After a reconnection, records missing from a counter that went on count as dropped; a
        counter (or device clock) that starts again lower restarted, and counts nothing."""
        self._restored = True

    def accept(self, readings: Readings) -> None:
        """Readings handed on, in order, with the records discarded (corrupt or rejected) before each
        (`Readings.discarded`). A batch in order, as nearly all are, is checked whole; the others
        reading by reading."""
        count = len(readings)
        restored = self._restored and count > 0
        if self._unwrap is not None and readings.seqs is not None:
            self._count_gaps(readings.seqs, readings.discarded, restored)
        elif readings.device_times is not None:
            self._count_late(readings.device_times, restored)
        if count:
            self._restored = False
            self._discarded_since = 0
        self._discarded_since += readings.discarded.get(count, 0)

    def _count_gaps(self, seqs: list[int], discarded: dict[int, int], restored: bool) -> None:
        unwrap, counters = self._unwrap, self._counters
        fulls = unwrap.unwrap_many(seqs)  # type: ignore[union-attr]
        last = self._last_seq
        if restored and last is not None and fulls[0] <= last:
            unwrap.reset()  # type: ignore[union-attr]
            fulls = unwrap.unwrap_many(seqs)  # type: ignore[union-attr]
            last = None
        if not fulls or (last is not None and fulls == list(range(last + 1, last + 1 + len(fulls)))):
            self._last_seq = fulls[-1] if fulls else last
            return
        since = self._discarded_since
        for index, full in enumerate(fulls):
            since += discarded.get(index, 0)
            if last is None or full > last:
                if last is not None and full - last - 1 > since:
                    counters.dropped += full - last - 1 - since  # type: ignore[operator]
                last = full
            else:
                counters.out_of_order += 1
            since = 0
        self._last_seq = last

    def _count_late(self, device_times: list[float], restored: bool) -> None:
        last = None if restored else self._last_time
        if device_times and (last is None or device_times[0] > last) and all(map(lt, device_times, device_times[1:])):
            self._last_time = device_times[-1]
            return
        for device_time in device_times:
            if last is None or device_time > last:
                last = device_time
            else:
                self._counters.out_of_order += 1
        self._last_time = last


class LatencyHistogram:
    """Tracker-to-host latencies (s) in 10 us bins: median and 95th percentile in ms at any time.
    The counts are a plain array of integers: a consumer adds a handful of latencies at a time, for
    which numpy's per-call overhead would cost more than the counting."""

    def __init__(self) -> None:
        self._counts = array("q", bytes(8 * _BINS))
        self.count = 0

    def add_many(self, latencies_s: Iterable[float]) -> None:
        counts, last = self._counts, _BINS - 1
        for latency_s in latencies_s:
            counts[min(max(int(latency_s / _BIN_S), 0), last)] += 1
            self.count += 1

    def quantile_ms(self, q: float) -> float | None:
        if not self.count:
            return None
        index = int(np.searchsorted(np.cumsum(np.frombuffer(self._counts, dtype=np.int64)), q * self.count))
        return (index + 0.5) * _BIN_S * 1e3

    def summary(self) -> dict[str, Any]:
        return {"samples": self.count, "median_ms": self.quantile_ms(0.5), "p95_ms": self.quantile_ms(0.95)}
