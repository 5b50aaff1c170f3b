"""From a record's raw numbers to a reading in the rig's units, and the checks that keep impossible
values away from a predictor.

A `Reading` is one decoded record before its clock is mapped: the host's arrival time, the device's
own time and record counter where it sends them, the position in metres, the orientation as it
came (maybe not of unit norm), and the angular rate where the profile has one. `ReadingMaker` turns
the records a decoder found in one feed, their fields in profile order, into readings column by
column, picking and scaling with `map` and `itemgetter` rather than a Python loop per field or per
record (at 1000 records a second the decoding is most of the consumer's cost, and it runs cold, a
batch every few ms); `check_reading` says what is impossible about one.
Euler angles become a quaternion with plain float arithmetic (a call into scipy per sample would
cost more than the whole reading budget).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import repeat
from operator import itemgetter, mul
from typing import Callable, Sequence

from predictors.scalar_quaternion import Quaternion, multiply
from rig.board.clock_sync import TickUnwrapper
from rig.devices.trackers.profile import (
    EULER,
    METRES_PER,
    POSITION,
    QUATERNION,
    RADIANS_PER,
    RATE,
    SECONDS_PER,
    SEQUENCE,
    TIME,
    Profile,
)


@dataclass(slots=True)
class Reading:
    """One decoded record: times in seconds (arrival on the rig clock, device on its own), metres,
    a (w, x, y, z) quaternion as received, rad/s."""

    t_arrival: float
    device_time: float | None
    seq: int | None
    position: tuple[float, float, float]
    orientation: Quaternion
    angular_rate: tuple[float, float, float] | None = None
    damaged_before: int = 0
    """Damaged records the decoder counted since the reading before this one: where in the stream
    they were, which a record counter's gaps are checked against."""


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
    """Turns records' values, in the profile's field order, into `Reading`s. Each group of fields
    (position, orientation, angular rate) is picked by index and multiplied by one factor per field
    (scale times unit), skipped where every factor is 1 and the fields are floats; an integer time
    field is unwrapped at its width (`reset` forgets its history)."""

    def __init__(self, profile: Profile) -> None:
        self._euler = profile.euler
        self._position = _group(profile, POSITION, METRES_PER[profile.position_unit])
        self._quaternion = _group(profile, QUATERNION, 1.0)
        self._euler_angles = _group(profile, EULER, RADIANS_PER[profile.angle_unit])
        self._rate = _group(profile, RATE, RADIANS_PER[profile.angle_unit])
        names = profile.names
        self._seq = names.index(SEQUENCE) if SEQUENCE in names else None
        self._time = names.index(TIME) if TIME in names else None
        time_field = profile.field(TIME)
        bits = time_field.integer_bits if time_field else None
        self._unwrap = TickUnwrapper(bits) if bits else None
        self._time_scale = profile.scale.get(TIME, 1.0)
        self._seconds = SECONDS_PER[profile.time_unit]

    def make_many(self, records: Sequence[Sequence[float]], arrivals: Sequence[float]) -> list[Reading]:
        """The readings of records, in order, each with its arrival, time fields (unwrapped) in seconds."""
        positions = repeat(_ORIGIN) if self._position is None else _column(self._position, records)
        if self._quaternion is not None:
            orientations = _column(self._quaternion, records)
        else:
            orientations = [euler_quaternion(self._euler, angles) for angles in _column(self._euler_angles, records)]  # type: ignore[arg-type]
        rates = repeat(None) if self._rate is None else _column(self._rate, records)
        seqs = repeat(None) if self._seq is None else map(int, map(itemgetter(self._seq), records))
        device_times: Sequence[float | None] | repeat[None] = repeat(None)
        if self._time is not None:
            raws = map(itemgetter(self._time), records)
            if self._unwrap is not None:
                raws = map(self._unwrap.unwrap, map(int, raws))
            scale, seconds = self._time_scale, self._seconds
            device_times = [raw * scale * seconds for raw in raws]
        return list(map(Reading, arrivals, device_times, seqs, positions, orientations, rates))

    def reset(self) -> None:
        """What follows comes from a device whose time counter may have started again."""
        if self._unwrap is not None:
            self._unwrap.reset()


_ORIGIN = (0.0, 0.0, 0.0)
_Group = tuple[Callable[[Sequence[float]], tuple], tuple[float, ...] | None]


def _group(profile: Profile, names: tuple[str, ...], unit: float) -> _Group | None:
    """How to pick the fields `names` out of a record's values, and their factors (None: all 1, on
    float fields); None where the profile has no such fields."""
    if not profile.has(*names):
        return None
    indices = [profile.names.index(name) for name in names]
    factors = tuple(profile.scale.get(name, 1.0) * unit for name in names)
    floats = all(profile.field(name).integer_bits is None for name in names)  # type: ignore[union-attr]
    return itemgetter(*indices), (None if floats and all(f == 1.0 for f in factors) else factors)


def _column(group: _Group, records: Sequence[Sequence[float]]) -> list[tuple]:
    """The group's fields of each record, times their factors."""
    pick, factors = group
    if factors is None:
        return list(map(pick, records))
    return [tuple(map(mul, pick(values), factors)) for values in records]


def check_reading(reading: Reading, unit_tolerance: float) -> str | None:
    """What makes the reading impossible (a number not finite, a quaternion not of unit norm within
    `unit_tolerance`), or None; a possible reading gets its quaternion normalised in place."""
    w, x, y, z = reading.orientation
    px, py, pz = reading.position
    wx, wy, wz = reading.angular_rate or (0.0, 0.0, 0.0)
    device_time = 0.0 if reading.device_time is None else reading.device_time
    if not math.isfinite(w + x + y + z + px + py + pz + wx + wy + wz + device_time):
        return f"a value is not a finite number: position {reading.position}, orientation {reading.orientation}"
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if abs(norm - 1.0) > unit_tolerance:
        return f"the quaternion {reading.orientation} has norm {norm:.6g}, not 1 within {unit_tolerance:g}"
    reading.orientation = (w / norm, x / norm, y / norm, z / norm)
    return None
