"""Records out of a tracker's byte stream, as its profile describes them, resynchronising after damage.

Each decoder is fed bytes as they arrive (`feed(data, t_arrival)`, or the chunks a reader queued
since the last feed, each with its arrival: `feed_chunks(chunks, arrivals)`) and returns the
readings of the records completed by them, each stamped with the arrival of the chunk that
completed it; what it could not decode it discards and counts in `corrupt`:

* `TextDecoder`: records end in the profile's terminator; a line with the wrong number of fields
  or a field that is not a number is one corrupt record. A line of the field names (a header) is
  skipped. A run of bytes longer than MAX_LINE without a terminator is corrupt.
* `BinaryDecoder`: records start with the sync bytes and have a fixed length. Where a checksum
  fails the decoder moves on by one byte and looks for the next sync, so a damaged record never
  takes an intact neighbour with it; a damaged stretch counts as the records its length could
  hold, rounded up (so garbage between records counts as one).
* `HidReportDecoder`: one input report is one record, after its report id where the device uses
  them; reports of other ids are someone else's and ignored, short ones are corrupt.

`reset()` forgets a partial record, counting it corrupt, and the time counter's history (after a
reconnection, or once the stream is closed).
"""

from __future__ import annotations

import math
import struct
from bisect import bisect_left
from itertools import accumulate
from typing import Sequence

from rig.devices.trackers.checksums import CHECK_BYTES, CHECKSUMS
from rig.devices.trackers.profile import Profile
from rig.devices.trackers.readings import Reading, ReadingMaker

MAX_LINE = 4096


class _RecordDecoder:
    """What every decoder does: counts damaged records (`corrupt`), makes the readings of the
    records a subclass decoded from one feed (`_made`), and tells each how many damaged records
    came since the reading before it."""

    def __init__(self, profile: Profile) -> None:
        self.corrupt = 0
        self._told = 0
        self._maker = ReadingMaker(profile)

    def feed(self, data: bytes, t_arrival: float) -> list[Reading]:
        """The readings of the records `data` completes, stamped `t_arrival`."""
        return self.feed_chunks((data,), (t_arrival,))

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> list[Reading]:
        """The readings of the records the chunks complete, in order, each stamped with the arrival of
        the chunk that completed it."""
        raise NotImplementedError

    def _made(self, records: list, arrivals: list[float], corrupt_at: list[int]) -> list[Reading]:
        """The readings of records decoded in one feed, each told the damaged records counted since
        the reading before it (`corrupt_at`: the count `corrupt` had when each was decoded)."""
        readings = self._maker.make_many(records, arrivals)
        if corrupt_at and corrupt_at[-1] != self._told:
            told = self._told
            for reading, corrupt in zip(readings, corrupt_at):
                reading.damaged_before = corrupt - told
                told = corrupt
            self._told = told
        return readings


class TextDecoder(_RecordDecoder):
    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._terminator = profile.terminator
        self._separator = profile.separator
        self._count = len(profile.fields)
        self._header = [name.encode("ascii", "replace") for name in profile.names]
        self._buffer = bytearray()

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> list[Reading]:
        buffer = self._buffer
        ends = _append_chunks(buffer, chunks)
        records: list[list[float]] = []
        times: list[float] = []
        corrupt_at: list[int] = []
        terminator = self._terminator
        start = 0
        while (end := buffer.find(terminator, start)) >= 0:
            values = self._values(bytes(buffer[start:end]))
            start = end + len(terminator)
            if values is not None:
                records.append(values)
                times.append(arrivals[bisect_left(ends, start)])
                corrupt_at.append(self.corrupt)
        del buffer[:start]
        if len(buffer) > MAX_LINE:
            buffer.clear()
            self.corrupt += 1
        return self._made(records, times, corrupt_at)

    def _values(self, line: bytes) -> list[float] | None:
        """A line's numbers, or None (counted corrupt unless it is blank or the header)."""
        parts = line.split(self._separator.encode("ascii")) if self._separator else line.split()
        if len(parts) != self._count:
            self.corrupt += bool(line.strip())
            return None
        try:
            return list(map(float, parts))
        except ValueError:
            self.corrupt += [part.strip() for part in parts] != self._header
            return None

    def reset(self) -> None:
        self.corrupt += bool(self._buffer.strip())
        self._buffer.clear()
        self._maker.reset()


class BinaryDecoder(_RecordDecoder):
    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._sync = profile.sync
        self._body = struct.Struct(profile.struct_format)
        self._check = CHECKSUMS[profile.checksum]
        self._check_bytes = CHECK_BYTES[profile.checksum]
        self._order = profile.byte_order
        self.record_bytes = len(self._sync) + self._body.size + self._check_bytes
        self._buffer = bytearray()
        self._discarded = 0

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> list[Reading]:
        buffer = self._buffer
        ends = _append_chunks(buffer, chunks)
        records: list[tuple] = []
        times: list[float] = []
        corrupt_at: list[int] = []
        sync, size = self._sync, self.record_bytes
        body_start, body_end = len(sync), size - self._check_bytes
        check, check_bytes, order, unpack_from = self._check, self._check_bytes, self._order, self._body.unpack_from
        start = 0
        while True:
            found = buffer.find(sync, start)
            if found < 0:
                keep = max(start, len(buffer) - len(sync) + 1)
                self._discarded += keep - start
                start = keep
                break
            self._discarded += found - start
            start = found
            end = start + size
            if len(buffer) < end:
                break
            if check_bytes and check(buffer[start + body_start : start + body_end], order) != buffer[start + body_end : end]:
                self._discarded += 1
                start += 1
                continue
            if self._discarded:
                self._end_stretch()
            records.append(unpack_from(buffer, start + body_start))
            times.append(arrivals[bisect_left(ends, end)])
            corrupt_at.append(self.corrupt)
            start = end
        del buffer[:start]
        return self._made(records, times, corrupt_at)

    def _end_stretch(self) -> None:
        self.corrupt += math.ceil(self._discarded / self.record_bytes)
        self._discarded = 0

    def reset(self) -> None:
        self._discarded += len(self._buffer)
        if self._discarded:
            self._end_stretch()
        self._buffer.clear()
        self._maker.reset()


class HidReportDecoder(_RecordDecoder):
    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._report_id = profile.report_id
        self._body = struct.Struct(profile.struct_format)
        self.report_bytes = self._body.size + (1 if self._report_id else 0)

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> list[Reading]:
        """Each chunk is one report."""
        records: list[tuple] = []
        times: list[float] = []
        corrupt_at: list[int] = []
        for report, t_arrival in zip(chunks, arrivals):
            if self._report_id:
                if not report or report[0] != self._report_id:
                    continue
                report = report[1:]
            if len(report) < self._body.size:
                self.corrupt += 1
                continue
            records.append(self._body.unpack_from(report))
            times.append(t_arrival)
            corrupt_at.append(self.corrupt)
        return self._made(records, times, corrupt_at)

    def reset(self) -> None:
        self._maker.reset()


Decoder = TextDecoder | BinaryDecoder | HidReportDecoder


def _append_chunks(buffer: bytearray, chunks: Sequence[bytes]) -> list[int]:
    """Appends the chunks to `buffer`; where each ends in it, in order (a record whose last byte is
    before the end of chunk k, and after that of chunk k - 1, was completed by chunk k)."""
    ends = list(accumulate(map(len, chunks), initial=len(buffer)))
    buffer += b"".join(chunks)
    return ends[1:]


def decoder_for(profile: Profile) -> Decoder:
    return {"text": TextDecoder, "binary": BinaryDecoder, "hid": HidReportDecoder}[profile.format](profile)
