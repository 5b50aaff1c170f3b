"""Input checks shared by the predictors: prediction times and tracker samples as plain floats.

The predictors take anything shaped like a `PoseSample` (t_sensor, position (3,), orientation
(4,)). `PoseSample` already refuses NaN and non-unit values, but a look-alike need not, so each
predictor reads a sample through `read_sample`, which raises before any state changes: a bad sample
is refused and the filter is as it was.
"""

from __future__ import annotations

import math
from math import isfinite
from typing import Any

import numpy as np

from predictors.errors import PredictorError
from predictors.scalar_quaternion import Quaternion

_UNIT_TOLERANCE = 1e-6
_ROUNDING = 1e-12

Vector = tuple[float, float, float]


def finite_time(t: Any, name: str) -> float:
    """t as a float, or PredictorError naming the predictor if it is not a finite time."""
    try:
        seconds = float(t)
    except (TypeError, ValueError):
        seconds = math.nan
    if not isfinite(seconds):
        raise PredictorError(f"predictor {name!r} was asked for time {t!r}; pass a finite time in seconds")
    return seconds


def no_sample_yet(name: str) -> PredictorError:
    """The error for predict() before any update()."""
    return PredictorError(f"predictor {name!r} has no sample yet; call update(sample) before predict(t)")


def horizon(t: Any, newest: float | None, limit: float, name: str) -> tuple[float, float]:
    """(t, h): the time asked as a float and its horizon from the newest sample's time, clamped to
    [-limit, limit] (a drop-out holds the motion instead of flying away); PredictorError before the
    first sample or for a time that is not finite."""
    if newest is None:
        raise no_sample_yet(name)
    t = finite_time(t, name)
    h = t - newest
    return t, limit if h > limit else -limit if h < -limit else h


def read_sample(sample: Any, name: str) -> tuple[float, Vector, Quaternion]:
    """(t_sensor, position, orientation) of a sample as floats; PredictorError if any is unusable.

    The orientation must be finite and of unit norm to within 1e-6. It is renormalised unless it is
    unit to rounding already, so a PoseSample's quaternion passes through bit for bit.
    """
    try:
        t = float(sample.t_sensor)
        x, y, z = map(float, _components(sample.position))
        qw, qx, qy, qz = map(float, _components(sample.orientation))
    except (AttributeError, TypeError, ValueError):
        raise PredictorError(
            f"predictor {name!r} needs a PoseSample (t_sensor, position (3,), orientation (4,)), got {sample!r}"
        ) from None
    if not (isfinite(t) and isfinite(x) and isfinite(y) and isfinite(z)):
        raise PredictorError(f"predictor {name!r} was given a sample with a non-finite time or position; sample ignored")
    norm = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    if not abs(norm - 1.0) <= _UNIT_TOLERANCE:
        raise PredictorError(
            f"predictor {name!r} was given an orientation of norm {norm!r}, not a unit quaternion; "
            "sample ignored: normalise it first"
        )
    if abs(norm - 1.0) > _ROUNDING:
        qw, qx, qy, qz = qw / norm, qx / norm, qy / norm, qz / norm
    return t, (x, y, z), (qw, qx, qy, qz)


def _components(values: Any) -> Any:
    """An array's values as Python floats (tolist is much faster than iterating an array)."""
    return values.tolist() if isinstance(values, np.ndarray) else values
