"""`split`: position as `adaptive` predicts it, orientation by the damped Kalman filter of `kalman-cv`.

Why two predictors: on people walking in one headset (a Quest Pro, orientation rounded to about
0.1 degree at 71 Hz), scored by person with each design chosen on the other people (`rig bench
predictors --corpus ... --cross-validate`, docs/predictor-validation.md), the two parts want
different things. Position gains most from `adaptive`'s choice, learnt on the stream, of how much to
smooth at each horizon. Orientation there gains a little from a velocity that dies away as a head's
turn does (the damped model of `predictors.kalman`, `angular_velocity_damping`), and never does
worse than constant velocity, where `adaptive`'s orientation, which at its shortest horizon keeps
constant velocity until another model beats it by a margin, can end a hair above it at 20 ms.
On other motion (another headset, a robot, the pendulum, clean synthetic streams) `adaptive`'s
orientation is the better one, which is why `split` is a candidate and not the default. Each part is
predicted exactly as its predictor would predict it alone; the cost is `adaptive`'s plus one
orientation filter.

Sample rules are each part's own (`predictors.adaptive`; the orientation filter's are those of
`predictors.kalman`, kept here): both drop a sample older than the newest and restart after a gap
longer than `max_gap`; a bad sample is refused before either part changes.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, ClassVar

from predictors.adaptive import GAIN_PRIOR, MARGIN, MEMORY, Adaptive
from predictors.checks import horizon, read_sample
from predictors.extrapolators import MIN_INTERVAL
from predictors.kalman import ANGULAR_ACCELERATION_NOISE, ANGULAR_VELOCITY_DAMPING, ORIENTATION_NOISE, OrientationFilter
from predictors.params import MAX_GAP, MAX_HORIZON, ParamSet, declare_params
from predictors.pose import Pose, PoseSample

SPLIT_DAMPING = replace(
    ANGULAR_VELOCITY_DAMPING, default=4.0, trainable=False,
    doc="The rate at which the angular velocity reverts to rest between its random changes (see "
    "`predictors.kalman`); the default is the rate chosen among 2, 4 and 8 per second by "
    "cross-validation over people (docs/predictor-validation.md).",
)  # fmt: skip
_ADAPTIVE = ("memory", "margin", "gain_prior", "min_interval", "max_gap", "max_horizon")


@declare_params(
    ORIENTATION_NOISE, ANGULAR_ACCELERATION_NOISE, SPLIT_DAMPING, MEMORY, MARGIN, GAIN_PRIOR, MIN_INTERVAL, MAX_GAP,
    MAX_HORIZON,
)  # fmt: skip
class Split:
    """Position from `adaptive`, orientation from `kalman-cv`'s filter with a damped angular velocity (`split`)."""

    name = "split"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self._position = Adaptive(**{k: getattr(self, k) for k in _ADAPTIVE})
        self.reset()

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample into both parts (refused, both unchanged, if it is bad); the
        orientation filter follows the sample rules of `predictors.kalman`."""
        t, _, orientation = read_sample(sample, self.name)
        self._position.update(sample)
        last = self._t
        if last is None or t - last > self.max_gap:
            self._orientation = OrientationFilter(self.orientation_noise, self.angular_acceleration_noise, orientation,
                                                  self.angular_velocity_damping)  # fmt: skip
            self._t = t
            return
        dt = t - last
        if dt < 0.0:
            return
        self._orientation.step(dt, orientation)  # type: ignore[union-attr]
        self._t = t

    def predict(self, t: float) -> Pose:
        """The pose at t (s): adaptive's position, the damped filter's orientation, at most
        max_horizon seconds from the newest sample."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        return Pose(t, self._position.position_at(t), self._orientation.at(h))  # type: ignore[union-attr]

    def reset(self) -> None:
        """Forget every sample and everything learnt."""
        self._position.reset()
        self._orientation: OrientationFilter | None = None
        self._t: float | None = None
