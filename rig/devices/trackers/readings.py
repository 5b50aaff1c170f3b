"""From records' raw numbers to readings in the rig's units, and the checks that keep impossible
values away from a predictor.

`Readings` are the records a decoder found in one feed before their clock is mapped, column by
column: the host's arrival times, the device's own times and record counters where it sends them,
positions in metres, orientations as they came (maybe not of unit norm), and angular rates where the
profile has them. `ReadingMaker` picks and scales the columns with `map` and `itemgetter` rather
than a Python loop per field or per record (at 1000 records a second the decoding is most of the
consumer's cost, and it runs cold, a batch every few ms); `keep_possible` removes the impossible
ones, in one loop over the batch that normalises the quaternions as it checks them, and says what is
wrong with each reading only where that loop finds something. Euler angles become a quaternion with
plain float arithmetic (a call into scipy per sample would cost more than the whole reading budget).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial
from itertools import repeat
from operator import itemgetter, mul
from typing import Callable, Iterable, Sequence

from predictors.scalar_quaternion import Quaternion, multiply
from rig.board.clock_sync import TickUnwrapper
from rig.devices.trackers.profile import EULER, POSITION, QUATERNION, RATE, SEQUENCE, TIME, Profile


@dataclass(slots=True)
class Readings:
    """Records decoded together before their clock is mapped, column by column (a consumer takes
    about twenty at a time, and a Python call or object per record would cost more than the
    decoding): arrival times on the rig clock and the device's own times (s; None: it sends none),
    record counters (None: none), positions (m), (w, x, y, z) quaternions as received, angular
    rates (rad/s; None: none)."""

    arrivals: list[float]
    device_times: list[float] | None
    seqs: list[int] | None
    positions: list[tuple[float, float, float]]
    orientations: list[Quaternion]
    rates: list[tuple[float, float, float]] | None = None
    discarded: dict[int, int] = field(default_factory=dict)
    """Records discarded (damaged, or impossible) just before the reading at an index, the index
    after the last for those after it: where in the stream they were, which a record counter's
    gaps are checked against."""

    def __len__(self) -> int:
        return len(self.arrivals)


def axis_quaternion(axis: str, angle: float) -> Quaternion:
    """The rotation by `angle` (rad) about the x, y or z axis."""
    half = 0.5 * angle
    c, s = math.cos(half), math.sin(half)
    return {"x": (c, s, 0.0, 0.0), "y": (c, 0.0, s, 0.0), "z": (c, 0.0, 0.0, s)}[axis]


def euler_quaternion(sequence: str, angles: Sequence[float]) -> Quaternion:
    """The orientation of Euler angles (rad) in `sequence`: upper case intrinsic (the first rotation
    about a fixed axis, the next about the turned body's), lower case extrinsic (all about fixed
    axes), as scipy's Rotation.from_euler reads the same sequence."""
    turns = [axis_quaternion(axis.lower(), angle) for axis, angle in zip(sequence, angles)]
    if sequence.islower():
        turns.reverse()
    q = turns[0]
    for turn in turns[1:]:
        q = multiply(q, turn)
    return q


class ReadingMaker:
    """Turns records' values, in the profile's field order, into `Readings`. Each group of fields
    (position, orientation, angular rate) is picked by index and multiplied by one factor per field
    (scale times unit), skipped where every factor is 1 and the fields are floats; an integer time
    field (integers, as struct reads them) is unwrapped at its width (`reset` forgets its history)."""

    def __init__(self, profile: Profile) -> None:
        self._euler = profile.euler
        self._position = _group(profile, POSITION)
        self._quaternion = _group(profile, QUATERNION)
        self._euler_angles = _group(profile, EULER)
        self._rate = _group(profile, RATE)
        names = _value_names(profile)
        seq_field = profile.field(SEQUENCE)
        self._seq = itemgetter(names.index(SEQUENCE)) if seq_field else None
        self._seq_as_text = seq_field is not None and seq_field.integer_bits is None
        """A text counter is read as a float, and made a whole number."""
        self._time = itemgetter(names.index(TIME)) if TIME in names else None
        time_field = profile.field(TIME)
        bits = time_field.integer_bits if time_field else None
        self._unwrap = TickUnwrapper(bits) if bits else None
        self._time_scale = profile.scale.get(TIME, 1.0)
        self._seconds = profile.unit(TIME)

    def make_many(self, records: Sequence[Sequence[float]], arrivals: list[float], discarded: dict[int, int]) -> Readings:
        """The readings of records, in order, with their arrivals and the records discarded before
        them (`Readings.discarded`), time fields (unwrapped) in seconds."""
        positions = [_ORIGIN] * len(records) if self._position is None else _column(self._position, records)
        if self._quaternion is not None:
            orientations = _column(self._quaternion, records)
        else:
            orientations = [euler_quaternion(self._euler, angles) for angles in _column(self._euler_angles, records)]  # type: ignore[arg-type]
        rates = None if self._rate is None else _column(self._rate, records)
        seqs = None if self._seq is None else list(map(self._seq, records))
        if self._seq_as_text:
            seqs = list(map(int, seqs))  # type: ignore[arg-type]
        device_times = None
        if self._time is not None:
            raws: Iterable[float] = list(map(self._time, records))
            if self._unwrap is not None:
                raws = self._unwrap.unwrap_many(raws)  # type: ignore[arg-type]
            scale, seconds = self._time_scale, self._seconds
            if scale != 1.0:
                raws = map(mul, raws, repeat(scale))
            device_times = list(map(mul, raws, repeat(seconds)))
        return Readings(arrivals, device_times, seqs, positions, orientations, rates, discarded)

    def reset(self) -> None:
        """What follows comes from a device whose time counter may have started again."""
        if self._unwrap is not None:
            self._unwrap.reset()


_ORIGIN = (0.0, 0.0, 0.0)
_Group = tuple[Callable[[Sequence[float]], tuple], tuple[float, ...] | None]


def _value_names(profile: Profile) -> list[str]:
    """The names of the fields that give a value, in order: a record's values skip its padding."""
    return [f.name for f in profile.fields if not f.code.endswith("x")]


def _group(profile: Profile, names: tuple[str, ...]) -> _Group | None:
    """How to pick the fields `names` out of a record's values, and their factors (None: all 1, on
    float fields); None where the profile has no such fields."""
    if not profile.has(*names):
        return None
    indices = [_value_names(profile).index(name) for name in names]
    factors = tuple(profile.scale.get(name, 1.0) * profile.unit(name) for name in names)
    floats = all(profile.field(name).integer_bits is None for name in names)  # type: ignore[union-attr]
    return itemgetter(*indices), (None if floats and all(f == 1.0 for f in factors) else factors)


def _column(group: _Group, records: Sequence[Sequence[float]]) -> list[tuple]:
    """The group's fields of each record, times their factors."""
    pick, factors = group
    if factors is None:
        return list(map(pick, records))
    return [tuple(map(mul, pick(values), factors)) for values in records]


def keep_possible(readings: Readings, unit_tolerance: float) -> list[str]:
    """Removes the impossible readings (a number not finite, a quaternion not of unit norm within
    `unit_tolerance`), each counted discarded before the next, and normalises the quaternions of the
    rest, in place; what was wrong with each removed, in order. One loop over the batch (absent
    rates and time add zeros), for the reason in `rig.devices.trackers.decoders.BinaryDecoder`."""
    normalised: list[Quaternion] = []
    impossible: list[int] = []
    append, sqrt, isfinite = normalised.append, math.sqrt, math.isfinite
    rates = readings.rates or repeat(_ORIGIN)
    times = readings.device_times or repeat(0.0)
    for (w, x, y, z), (px, py, pz), (wx, wy, wz), t in zip(readings.orientations, readings.positions, rates, times):
        norm = sqrt(w * w + x * x + y * y + z * z)
        if isfinite(w + x + y + z + px + py + pz + wx + wy + wz + t) and abs(norm - 1.0) <= unit_tolerance:
            append((w / norm, x / norm, y / norm, z / norm))
        else:
            impossible.append(len(normalised) + len(impossible))
    problems = [_problem(readings.positions[k], readings.orientations[k], unit_tolerance) for k in impossible]
    if impossible:
        _remove(readings, impossible)
    readings.orientations = normalised
    return problems


def _problem(position: tuple[float, float, float], orientation: Quaternion, unit_tolerance: float) -> str:
    """What makes an impossible reading so."""
    norm = math.sqrt(sum(q * q for q in orientation))
    if all(map(math.isfinite, (*position, *orientation))) and abs(norm - 1.0) > unit_tolerance:
        return f"the quaternion {orientation} has norm {norm:.6g}, not 1 within {unit_tolerance:g}"
    return f"a value is not a finite number: position {position}, orientation {orientation}"


def _remove(readings: Readings, impossible: list[int]) -> None:
    """Leaves out the readings at the (sorted) indices `impossible` in every column but the
    orientations, and tells each removed one, with the damage before it, to the next one kept."""
    count = len(readings)
    dropped = set(impossible)
    kept: list[int] = []
    discarded: dict[int, int] = {}
    pending = 0
    for index in range(count):
        pending += readings.discarded.get(index, 0)
        if index in dropped:
            pending += 1
            continue
        if pending:
            discarded[len(kept)], pending = pending, 0
        kept.append(index)
    pending += readings.discarded.get(count, 0)
    if pending:
        discarded[len(kept)] = pending
    pick = partial(_pick, kept)
    readings.arrivals, readings.positions = pick(readings.arrivals), pick(readings.positions)
    if readings.device_times is not None:
        readings.device_times = pick(readings.device_times)
    if readings.seqs is not None:
        readings.seqs = pick(readings.seqs)
    if readings.rates is not None:
        readings.rates = pick(readings.rates)
    readings.discarded = discarded


def _pick(indices: list[int], column: list) -> list:
    return list(map(column.__getitem__, indices))
