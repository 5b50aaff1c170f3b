"""Records out of a tracker's byte stream, as its profile describes them, resynchronising after damage.

A decoder is pure: no device, no thread, no clock. It is fed the chunks a reader queued since the
last feed, each with its arrival (`feed_chunks(chunks, arrivals)`, or one: `feed(data, t_arrival)`),
and returns the readings of the records completed by them, each stamped with the arrival of the
chunk that completed it; what it could not decode it discards and counts in `corrupt`. Tests feed
it transcripts. `decoder_for(profile)` gives a profile's:

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
from itertools import accumulate, chain, repeat
from operator import add
from typing import Protocol, Sequence

from rig.devices.trackers.checksums import CHECK_BYTES, CHECK_CODES, CHECK_VALUES
from rig.devices.trackers.profile import Profile
from rig.devices.trackers.readings import ReadingMaker, Readings

MAX_LINE = 4096


class Decoder(Protocol):
    """What a tracker stream reads its transport's chunks with."""

    corrupt: int

    def feed_chunks(self, chunks: Sequence, arrivals: Sequence[float]) -> Readings:
        """The readings of the records the chunks complete, in order, each stamped with the arrival
        of the chunk that completed it."""

    def reset(self) -> None:
        """Forgets a partial record (counting it corrupt) and the time counter's history."""


class _RecordDecoder:
    """What every decoder does: counts damaged records (`corrupt`), and tells the readings it makes
    how many damaged records came before each (`Readings.discarded`)."""

    def __init__(self, profile: Profile) -> None:
        self.corrupt = 0
        self._told = 0
        self._maker = ReadingMaker(profile)

    def feed(self, data: bytes, t_arrival: float) -> Readings:
        """The readings of the records `data` completes, stamped `t_arrival`."""
        return self.feed_chunks((data,), (t_arrival,))

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> Readings:
        """The readings of the records the chunks complete, in order, each stamped with the arrival of
        the chunk that completed it."""
        raise NotImplementedError

    def _tell_damage(self, index: int, discarded: dict[int, int]) -> None:
        """The damaged records counted since the last reading made came just before reading `index`."""
        if self.corrupt != self._told:
            discarded[index] = self.corrupt - self._told
            self._told = self.corrupt


class TextDecoder(_RecordDecoder):
    """Splits what arrived into lines at once and reads all their numbers in one pass; a feed with a
    line that does not read as a record (damage, a header, a blank) is read line by line."""

    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._terminator = profile.terminator
        self._separator = profile.separator.encode("ascii") if profile.separator else None
        self._count = len(profile.fields)
        self._header = [name.encode("ascii", "replace") for name in profile.names]
        self._rest = b""

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> Readings:
        data, ends = _joined(self._rest, chunks)
        terminator = self._terminator
        last = data.rfind(terminator)
        lines = data[:last].split(terminator) if last >= 0 else []
        self._rest = data[last + len(terminator) :] if last >= 0 else data
        step = len(terminator)
        line_ends = map(add, accumulate(map(len, lines)), range(step, (len(lines) + 1) * step, step))
        times = list(map(arrivals.__getitem__, map(bisect_left, repeat(ends), line_ends)))
        discarded: dict[int, int] = {}
        records = self._read_all(lines)
        if records is None:
            records, times = self._read_each(lines, times, discarded)
        elif records:
            self._tell_damage(0, discarded)
        if len(self._rest) > MAX_LINE:
            self._rest = b""
            self.corrupt += 1
        return self._maker.make_many(records, times, discarded)

    def _read_all(self, lines: list[bytes]) -> list[tuple[float, ...]] | None:
        """Every line's numbers, or None unless each line has the profile's number of fields, all
        numbers."""
        rows = [line.split(self._separator) for line in lines]
        count = self._count
        if not all(map(count.__eq__, map(len, rows))):
            return None
        try:
            values = list(map(float, chain.from_iterable(rows)))
        except ValueError:
            return None
        return list(zip(*[iter(values)] * count))

    def _read_each(self, lines: list[bytes], times: list[float], discarded: dict[int, int]) -> tuple[list, list[float]]:
        records, kept_times = [], []
        for line, t_arrival in zip(lines, times):
            values = self._values(line)
            if values is not None:
                self._tell_damage(len(records), discarded)
                records.append(values)
                kept_times.append(t_arrival)
        return records, kept_times

    def _values(self, line: bytes) -> list[float] | None:
        """A line's numbers, or None (counted corrupt unless it is blank or the header)."""
        parts = line.split(self._separator)
        if len(parts) != self._count:
            self.corrupt += bool(line.strip())
            return None
        try:
            return list(map(float, parts))
        except ValueError:
            self.corrupt += [part.strip() for part in parts] != self._header
            return None

    def reset(self) -> None:
        self.corrupt += bool(self._rest.strip())
        self._rest = b""
        self._maker.reset()


class BinaryDecoder(_RecordDecoder):
    """Reads record after record in one loop that calls as few distinct functions as it can: the
    consumer runs it every 20 ms or so, cold, and there every distinct function costs several
    microseconds to bring back into the caches, more than a record's decoding (a batch of numpy
    or itertools steps costs more than it saves)."""

    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._sync = profile.sync
        body = profile.struct_format
        self._record = struct.Struct(f"{body[0]}{len(self._sync)}x{body[1:]}{CHECK_CODES[profile.checksum]}")
        """The whole record: the body's fields, then the check as a number (no field: sync, padding)."""
        self._check = CHECK_VALUES[profile.checksum]
        self.record_bytes = self._record.size
        self._body_span = (len(self._sync), self.record_bytes - CHECK_BYTES[profile.checksum])
        self._rest = b""
        self._discarded = 0

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> Readings:
        rest = self._rest
        data = rest + b"".join(chunks)
        records: list[tuple] = []
        times: list[float] = []
        discarded: dict[int, int] = {}
        sync, size, unpack, check = self._sync, self.record_bytes, self._record.unpack_from, self._check
        body_start, body_end = self._body_span
        # The chunk that holds the end of the record (`chunk`), and where that chunk ends in `data`.
        chunk, chunk_end = 0, len(rest) + (len(chunks[0]) if chunks else 0)
        start = 0
        while True:
            found = data.find(sync, start)
            if found < 0:
                keep = max(start, len(data) - len(sync) + 1)
                self._discarded += keep - start
                start = keep
                break
            self._discarded += found - start
            start = found
            end = start + size
            if len(data) < end:
                break
            values = unpack(data, start)
            if check is not None and check(data[start + body_start : start + body_end]) != values[-1]:
                self._discarded += 1
                start += 1
                continue
            if self._discarded:
                self._end_stretch()
            if self.corrupt != self._told:
                self._tell_damage(len(records), discarded)
            while chunk_end < end:
                chunk += 1
                chunk_end += len(chunks[chunk])
            records.append(values)
            times.append(arrivals[chunk])
            start = end
        self._rest = data[start:]
        return self._maker.make_many(records, times, discarded)

    def _end_stretch(self) -> None:
        self.corrupt += math.ceil(self._discarded / self.record_bytes)
        self._discarded = 0

    def reset(self) -> None:
        self._discarded += len(self._rest)
        if self._discarded:
            self._end_stretch()
        self._rest = b""
        self._maker.reset()


class HidReportDecoder(_RecordDecoder):
    def __init__(self, profile: Profile) -> None:
        super().__init__(profile)
        self._report_id = profile.report_id
        self._body = struct.Struct(profile.struct_format)
        self.report_bytes = self._body.size + (1 if self._report_id else 0)

    def feed_chunks(self, chunks: Sequence[bytes], arrivals: Sequence[float]) -> Readings:
        """Each chunk is one report."""
        records: list[tuple] = []
        times: list[float] = []
        discarded: dict[int, int] = {}
        for report, t_arrival in zip(chunks, arrivals):
            if self._report_id:
                if not report or report[0] != self._report_id:
                    continue
                report = report[1:]
            if len(report) < self._body.size:
                self.corrupt += 1
                continue
            self._tell_damage(len(records), discarded)
            records.append(self._body.unpack_from(report))
            times.append(t_arrival)
        return self._maker.make_many(records, times, discarded)

    def reset(self) -> None:
        self._maker.reset()


def _joined(rest: bytes, chunks: Sequence[bytes]) -> tuple[bytes, list[int]]:
    """What was left of earlier feeds with the chunks after it, and where each chunk ends in that (a
    record whose last byte is before the end of chunk k, and after that of chunk k - 1, was
    completed by chunk k)."""
    ends = list(accumulate(map(len, chunks), initial=len(rest)))
    return rest + b"".join(chunks), ends[1:]


def decoder_for(profile: Profile) -> TextDecoder | BinaryDecoder | HidReportDecoder:
    return {"text": TextDecoder, "binary": BinaryDecoder, "hid": HidReportDecoder}[profile.format](profile)
