"""From a record's raw numbers to a reading in the rig's units, and the checks that keep impossible
values away from a predictor.

A `Reading` is one decoded record before its clock is mapped: the host's arrival time, the device's
own time and record counter where it sends them, the position in metres, the orientation as it
came (maybe not of unit norm), and the angular rate where the profile has one. `ReadingMaker` turns
the record's fields, in profile order, into one; `check_reading` says what is impossible about it.
Euler angles become a quaternion with plain float arithmetic (a call into scipy per sample would
cost more than the whole reading budget).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

from predictors.scalar_quaternion import Quaternion, multiply
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
    """Turns a record's values, in the profile's field order, into a `Reading`."""

    def __init__(self, profile: Profile) -> None:
        names = profile.names
        self._profile = profile
        self._scale = [profile.scale.get(name, 1.0) for name in names]
        self._position = [names.index(n) for n in POSITION] if profile.has(*POSITION) else None
        self._quaternion = [names.index(n) for n in QUATERNION] if profile.has(*QUATERNION) else None
        self._euler = [names.index(n) for n in EULER] if profile.has(*EULER) else None
        self._rate = [names.index(n) for n in RATE] if profile.has(*RATE) else None
        self._time = names.index(TIME) if TIME in names else None
        self._seq = names.index(SEQUENCE) if SEQUENCE in names else None
        self._metres = METRES_PER[profile.position_unit]
        self._radians = RADIANS_PER[profile.angle_unit]
        self._seconds = SECONDS_PER[profile.time_unit]

    @property
    def has_device_time(self) -> bool:
        return self._time is not None

    def raw_device_time(self, values: Sequence[float]) -> float | None:
        """The time field as sent, before scale and unit (an integer counter may wrap)."""
        return None if self._time is None else values[self._time]

    def make(self, values: Sequence[float], t_arrival: float, device_time: float | None) -> Reading:
        """A reading of `values`; `device_time` is the time field in seconds after unwrapping."""
        scale = self._scale
        if self._position is None:
            position = (0.0, 0.0, 0.0)
        else:
            m = self._metres
            x, y, z = (values[i] * scale[i] * m for i in self._position)
            position = (x, y, z)
        if self._quaternion is not None:
            w, x, y, z = (values[i] * scale[i] for i in self._quaternion)
            orientation = (w, x, y, z)
        else:
            r = self._radians
            orientation = euler_quaternion(self._profile.euler, [values[i] * scale[i] * r for i in self._euler])
        rate = None
        if self._rate is not None:
            r = self._radians
            wx, wy, wz = (values[i] * scale[i] * r for i in self._rate)
            rate = (wx, wy, wz)
        seq = None if self._seq is None else int(values[self._seq])
        return Reading(t_arrival, device_time, seq, position, orientation, rate)

    def seconds(self, raw_time: float) -> float:
        """A time field's value (after unwrapping) in seconds."""
        assert self._time is not None
        return raw_time * self._scale[self._time] * self._seconds


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
