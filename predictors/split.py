"""`split`: position as `adaptive` predicts it, orientation by the damped Kalman filter of `kalman-cv`.

Why two predictors: on people walking in a headset, scored by person with each design chosen on
the other people (`rig bench predictors --corpus ... --cross-validate`, docs/predictor-validation.md),
the two parts want different things. Position, whose tracker noise varies from one headset to the
next, gains most from `adaptive`'s choice, learnt on the stream, of how much to smooth at each
horizon. Orientation gains most from a velocity that dies away as a head's turn does (the damped
model of `predictors.kalman`, `angular_velocity_damping`), and `adaptive`'s orientation, which at
its shortest horizon keeps constant velocity until another model beats it by a margin, can end up
a hair worse than constant velocity at 20 ms on a person. Each part is predicted exactly as its
predictor would predict it alone.

Sample rules are each part's own (`predictors.adaptive`, `predictors.kalman`): both drop a sample
older than the newest and restart after a gap longer than `max_gap`; a bad sample is refused before
either part changes.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, ClassVar

from predictors.adaptive import GAIN_PRIOR, MARGIN, MEMORY, Adaptive
from predictors.checks import finite_time, no_sample_yet, read_sample
from predictors.extrapolators import MIN_INTERVAL
from predictors.kalman import ANGULAR_ACCELERATION_NOISE, ANGULAR_VELOCITY_DAMPING, ORIENTATION_NOISE, KalmanCV
from predictors.params import MAX_GAP, MAX_HORIZON, ParamSet, declare_params
from predictors.pose import Pose, PoseSample

SPLIT_DAMPING = replace(
    ANGULAR_VELOCITY_DAMPING, default=4.0, trainable=False,
    doc="The rate at which the angular velocity reverts to rest between its random changes (see "
    "`predictors.kalman`); the default is the one chosen by cross-validation over people "
    "(docs/predictor-validation.md).",
)  # fmt: skip
_ADAPTIVE = ("memory", "margin", "gain_prior", "min_interval", "max_gap", "max_horizon")
_ORIENTATION = ("orientation_noise", "angular_acceleration_noise", "max_gap", "max_horizon")


@declare_params(
    ORIENTATION_NOISE, ANGULAR_ACCELERATION_NOISE, SPLIT_DAMPING, MEMORY, MARGIN, GAIN_PRIOR, MIN_INTERVAL, MAX_GAP,
    MAX_HORIZON,
)  # fmt: skip
class Split:
    """Position from `adaptive`, orientation from `kalman-cv` with a damped angular velocity (`split`)."""

    name = "split"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self._position = Adaptive(**{k: getattr(self, k) for k in _ADAPTIVE})
        self._orientation = KalmanCV(angular_velocity_damping=self.angular_velocity_damping,
                                     **{k: getattr(self, k) for k in _ORIENTATION})  # fmt: skip
        self._started = False

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample into both parts (refused, both unchanged, if it is bad)."""
        read_sample(sample, self.name)
        self._position.update(sample)
        self._orientation.update(sample)
        self._started = True

    def predict(self, t: float) -> Pose:
        """The pose at t (s): adaptive's position, the damped filter's orientation."""
        finite_time(t, self.name)
        if not self._started:
            raise no_sample_yet(self.name)
        position = self._position.predict(t)
        return Pose(position.t, position.position, self._orientation.predict(t).orientation)

    def reset(self) -> None:
        """Forget every sample and everything learnt."""
        self._position.reset()
        self._orientation.reset()
        self._started = False
