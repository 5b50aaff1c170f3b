"""Predictors that extrapolate from the newest samples: hold-last and slerp extrapolation.

Both order samples by sensor time (`PoseSample.t_sensor`), the time the pose was true:

* a sample older than the newest one is ignored, because it says nothing about where the pose is
  going that the newer sample has not already said (a late packet, a re-sent measurement);
* a sample at the newest one's time replaces it, because it arrived later.

Both answer any finite time, before or after the newest sample.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from predictors import scalar_quaternion as squat
from predictors.checks import finite_time, no_sample_yet, read_sample
from predictors.params import Param, ParamSet, Range, declare_params
from predictors.pose import Pose, PoseSample

MIN_INTERVAL = Param(
    "min_interval", 1e-6, "seconds",
    "A sample less than this after the newest one counts as a duplicate: it replaces the newest and "
    "the older, distinct sample is kept, so the two samples used are always at least this far apart "
    "and a repeated timestamp never divides by zero or amplifies jitter into a wild velocity.",
    Range(0.0, 1.0, includes_high=True),
)


@declare_params()
class HoldLast:
    """No prediction: every answer is the newest sample's pose, stamped with the asked time.

    The baseline every other predictor must beat.
    """

    name = "hold"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """No parameters: any keyword argument is refused, naming the predictor."""
        self.params.assign(self, values)
        self._newest: PoseSample | None = None
        self._t = 0.0

    def update(self, sample: PoseSample) -> None:
        t, _, _ = read_sample(sample, self.name)
        if self._newest is None or t >= self._t:
            self._newest = sample
            self._t = t

    def predict(self, t: float) -> Pose:
        newest = self._newest
        if newest is None:
            raise no_sample_yet(self.name)
        return Pose(finite_time(t, self.name), newest.position, newest.orientation)

    def reset(self) -> None:
        self._newest = None


# (t_sensor, position, orientation) of a sample, as floats.
_Reading = tuple[float, tuple[float, float, float], squat.Quaternion]


class _Motion:
    """Constant-velocity motion through two samples, anchored at the newer one (time t1).

    At t the pose is p1 + (t - t1) v and the orientation is cos(phi) q1 + sin(phi) tangent with
    phi = (t - t1) * rate: the great circle through q1 and q0, i.e. slerp(q0, q1, u) with
    u = (t - t0) / (t1 - t0), taken the short way. Anchoring at the newer sample makes t = t1
    return it exactly. Plain floats (`predictors.scalar_quaternion`): this runs once per display
    frame.
    """

    __slots__ = ("t1", "position", "velocity", "orientation", "tangent", "rate")

    def __init__(self, older: _Reading, newer: _Reading) -> None:
        t0, p0, q0 = older
        t1, p1, q1 = newer
        dt = t1 - t0
        # The great circle runs from q1 towards q0, so the future lies at negative phase.
        half_angle, tangent = squat.great_circle(q1, q0)
        self.t1 = t1
        self.position = p1
        self.velocity = ((p1[0] - p0[0]) / dt, (p1[1] - p0[1]) / dt, (p1[2] - p0[2]) / dt)
        self.orientation = q1
        self.tangent = tangent
        self.rate = -half_angle / dt

    def at(self, t: float) -> Pose:
        dt = t - self.t1
        phase = dt * self.rate
        c, s = math.cos(phase), math.sin(phase)
        (w, x, y, z), (tw, tx, ty, tz) = self.orientation, self.tangent
        (px, py, pz), (vx, vy, vz) = self.position, self.velocity
        return Pose(
            t,
            (px + dt * vx, py + dt * vy, pz + dt * vz),
            (c * w + s * tw, c * x + s * tx, c * y + s * ty, c * z + s * tz),
        )


@declare_params(MIN_INTERVAL)
class SlerpExtrapolator:
    """Linear prediction from the two newest samples (Smit et al. 2010, section 3.2).

    With samples (t0, p0, q0) and (t1, p1, q1), t0 < t1 by sensor time, the prediction for t is
    position p0 + u (p1 - p0) and orientation slerp(q0, q1, u), u = (t - t0) / (t1 - t0): constant
    linear and angular velocity, the rotation taken the short way (so q1 and -q1 predict alike).
    With a single sample it holds that sample.
    """

    name = "slerp"
    params: ClassVar[ParamSet]
    _older: _Reading | None
    _newest: _Reading | None
    _motion: _Motion | None

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self.reset()

    def update(self, sample: PoseSample) -> None:
        reading = read_sample(sample, self.name)
        newest = self._newest
        if newest is not None:
            step = reading[0] - newest[0]
            if step < 0.0:
                return
            if step >= self.min_interval:
                self._older = newest
        self._newest = reading
        self._motion = None

    def predict(self, t: float) -> Pose:
        newest = self._newest
        if newest is None:
            raise no_sample_yet(self.name)
        t = finite_time(t, self.name)
        if self._older is None:
            return Pose(t, newest[1], newest[2])
        if self._motion is None:
            self._motion = _Motion(self._older, newest)
        return self._motion.at(t)

    def reset(self) -> None:
        self._older = None
        self._newest = None
        self._motion = None
