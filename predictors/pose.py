"""Pose types: the plain values that flow from tracker to predictor to renderer.

Units and conventions (DESIGN.md): time in seconds on the rig clock, position in metres with shape
(3,), orientation a unit quaternion (w, x, y, z), Hamilton convention, rotating body into world.

Both types validate on construction and keep their own read-only float64 copies of the arrays, so
a pose handed on cannot change under its receiver. Validation reads the few components as Python
floats rather than calling numpy reductions: a pose is built once per display frame inside the
real-time budget, and numpy's per-call overhead on 3- and 4-vectors would be most of its cost.
"""

from __future__ import annotations

import math
import struct
from math import isfinite
from dataclasses import dataclass
from typing import Sequence, Union

import numpy as np

from predictors.errors import PredictorError

FloatVector = Union[np.ndarray, Sequence[float]]

_UNIT_TOLERANCE = 1e-6


_PACK3 = struct.Struct("3d").pack
_PACK4 = struct.Struct("4d").pack


def _float_array(value: FloatVector, what: str) -> np.ndarray:
    """A float64 copy of value, owned by the pose."""
    try:
        return np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise PredictorError(f"{what} must be numbers, got {value!r}") from None


def _finite(values: tuple[float, ...], what: str, part: str) -> bool:
    """Whether every value is finite; PredictorError if one is not a number."""
    try:
        return all(map(isfinite, values))
    except TypeError:
        raise PredictorError(f"{what}: {part} must be numbers, got {values!r}") from None


def _position(value: FloatVector, what: str) -> np.ndarray:
    if type(value) is tuple and len(value) == 3:
        # What the predictors return once per display frame: packed straight into an immutable
        # buffer, two numpy calls fewer than the general path.
        if not _finite(value, what, "position"):
            raise PredictorError(f"{what}: position must be finite, got {list(value)}")
        return np.frombuffer(_PACK3(*value))
    p = _float_array(value, f"{what}: position")
    if p.shape != (3,):
        raise PredictorError(f"{what}: position must have shape (3,), got {p.shape}")
    x, y, z = p.tolist()
    if not (isfinite(x) and isfinite(y) and isfinite(z)):
        raise PredictorError(f"{what}: position must be finite, got {[x, y, z]}")
    p.flags.writeable = False
    return p


def _orientation(value: FloatVector, what: str) -> np.ndarray:
    if type(value) is tuple and len(value) == 4:
        if not _finite(value, what, "orientation"):
            raise PredictorError(f"{what}: orientation must be finite, got {list(value)}")
        w, x, y, z = value
    else:
        q = _float_array(value, f"{what}: orientation")
        if q.shape != (4,):
            raise PredictorError(f"{what}: orientation must be a (w, x, y, z) quaternion, got shape {q.shape}")
        w, x, y, z = q.tolist()
        if not (isfinite(w) and isfinite(x) and isfinite(y) and isfinite(z)):
            raise PredictorError(f"{what}: orientation must be finite, got {[w, x, y, z]}")
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if abs(norm - 1.0) > _UNIT_TOLERANCE:
        raise PredictorError(
            f"{what}: orientation must be a unit quaternion, got norm {norm:.9g}; normalise it first"
        )
    if norm != 1.0:
        w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.frombuffer(_PACK4(w, x, y, z))


def _time(value: float, what: str) -> float:
    try:
        t = float(value)
    except (TypeError, ValueError):
        raise PredictorError(f"{what} must be a time in seconds, got {value!r}") from None
    if not math.isfinite(t):
        raise PredictorError(f"{what} must be a finite time in seconds, got {value!r}")
    return t


@dataclass(frozen=True, eq=False)
class Pose:
    """A pose at time `t` (s): position (m) and unit orientation quaternion (w, x, y, z)."""

    t: float
    position: np.ndarray
    orientation: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "t", _time(self.t, "Pose.t"))
        object.__setattr__(self, "position", _position(self.position, "Pose"))
        object.__setattr__(self, "orientation", _orientation(self.orientation, "Pose"))


@dataclass(frozen=True, eq=False)
class PoseSample:
    """A tracker measurement: when the sensor took it, when the host received it, and the pose."""

    t_sensor: float
    t_arrival: float
    position: np.ndarray
    orientation: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "t_sensor", _time(self.t_sensor, "PoseSample.t_sensor"))
        object.__setattr__(self, "t_arrival", _time(self.t_arrival, "PoseSample.t_arrival"))
        object.__setattr__(self, "position", _position(self.position, "PoseSample"))
        object.__setattr__(self, "orientation", _orientation(self.orientation, "PoseSample"))

    def pose(self) -> Pose:
        """The measured pose, stamped with the sensor time."""
        return Pose(self.t_sensor, self.position, self.orientation)
