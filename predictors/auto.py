"""`auto`: per scene, the simplest motion model that predicts as well as the best.

Candidates, run side by side on every sample:

* position: no prediction (the newest sample), constant velocity, constant acceleration (the
  Kalman position filters of `predictors.kalman`);
* orientation: no prediction (the newest sample), or the orientation filter of `kalman-cv`.

Each candidate's earlier prediction is scored against every sample that arrives: a filter's one-step
prediction error is its innovation, which it computes anyway, and no prediction's is the motion since
the previous sample, so scoring costs a few multiplications. The scores are exponentially weighted
mean squares with time constant `memory`. The choice is the simplest candidate whose RMS error is
within `margin` (a fraction) of the best plus the tracker's noise (position_noise or
orientation_noise: errors below the noise cannot tell models apart, and once motion stops every
score decays alike, so without it the history of the motion would decide); until `memory` seconds
of samples have been scored, it is the simplest. `choice` says what is in use and why.

Its cost per sample is one constant-velocity and one constant-acceleration position filter and one
orientation filter, less than `kalman-cv` and `kalman-ca` together. Sample order rules are those of
`predictors.kalman`; a gap longer than `max_gap` restarts the candidates and their scores.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, ClassVar

from predictors import scalar_quaternion as squat
from predictors.checks import horizon, read_sample
from predictors.kalman import (
    ACCELERATION_NOISE,
    ANGULAR_ACCELERATION_NOISE,
    ANGULAR_VELOCITY_DAMPING,
    JERK_NOISE,
    ORIENTATION_NOISE,
    POSITION_NOISE,
    ConstantAccelerationPosition,
    ConstantVelocityPosition,
    OrientationFilter,
)
from predictors.params import LOG, MAX_GAP, MAX_HORIZON, Param, ParamSet, Range, declare_params
from predictors.pose import Pose, PoseSample

POSITION_MODELS = ("none", "constant-velocity", "constant-acceleration")
ORIENTATION_MODELS = ("none", "filter")

# Tuning fits auto's filters as kalman-cv's, which has no jerk.
AUTO_JERK_NOISE = replace(
    JERK_NOISE, trainable=False, doc=f"{JERK_NOISE.doc} Tuning auto leaves it as given: tune kalman-ca for it."
)
# Both choose between models, so tuning searches them on a grid (log-spaced: both act multiplicatively).
MEMORY = Param(
    "memory", 2.0, "seconds",
    "Time constant of the error scores, and how long a cold start uses the simplest models before choosing.",
    Range(1e-3, 3600.0, True, True), LOG, trainable=True,
)
MARGIN = Param(
    "margin", 0.1, "",
    "A fraction: a simpler model is used while its RMS error is at most (1 + margin) times the best "
    "one's plus the tracker's noise.",
    Range(1e-4, 100.0, True, True), LOG, trainable=True,
)


@dataclass(frozen=True)
class AutoChoice:
    """The models `auto` predicts with now, and why (RMS one-step errors in mm and degrees)."""

    position: str
    orientation: str
    reason: str


def _simplest_within(mean_squares: list[float], margin: float, noise: float) -> int:
    """Index of the simplest score within the bound: the best one is always within it, so when no
    simpler one is, the last is the best. A plain loop, as this runs per sample."""
    bound = (1.0 + margin) * math.sqrt(min(mean_squares)) + noise
    bound *= bound
    last = len(mean_squares) - 1
    for i in range(last):
        if mean_squares[i] <= bound:
            return i
    return last


@declare_params(
    POSITION_NOISE, ACCELERATION_NOISE, AUTO_JERK_NOISE, ORIENTATION_NOISE, ANGULAR_ACCELERATION_NOISE,
    ANGULAR_VELOCITY_DAMPING, MARGIN, MEMORY, MAX_GAP, MAX_HORIZON,
)
class Auto:
    """Chooses per scene between no prediction, constant velocity and constant acceleration for
    position, and whether to filter orientation at all (`auto`).

    The filters' parameters are those of `kalman-cv` and `kalman-ca`.
    """

    name = "auto"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and every score."""
        self._t: float | None = None
        self._start = 0.0
        self._position: tuple[float, float, float] = (0.0, 0.0, 0.0)
        self._orientation: squat.Quaternion = squat.IDENTITY
        self._cv: ConstantVelocityPosition | None = None
        self._ca: ConstantAccelerationPosition | None = None
        self._filter: OrientationFilter | None = None
        self._position_scores = [0.0, 0.0, 0.0]
        self._orientation_scores = [0.0, 0.0]
        self._position_model = 0
        self._orientation_model = 0

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample, score every candidate on it, and choose."""
        t, position, orientation = read_sample(sample, self.name)
        last = self._t
        if last is None or t - last > self.max_gap:
            self.reset()
            self._cv = ConstantVelocityPosition(self.position_noise, self.acceleration_noise, position)
            self._ca = ConstantAccelerationPosition(self.position_noise, self.jerk_noise, position)
            self._filter = OrientationFilter(
                self.orientation_noise, self.angular_acceleration_noise, orientation, self.angular_velocity_damping
            )
            self._t = self._start = t
            self._position, self._orientation = position, orientation
            return
        dt = t - last
        if dt < 0.0:
            return
        px, py, pz = self._position
        still_position = (position[0] - px) ** 2 + (position[1] - py) ** 2 + (position[2] - pz) ** 2
        a, b = self._orientation, orientation
        dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
        still_orientation = 4.0 * max(0.0, 1.0 - dot * dot)  # 4 sin^2(angle / 2), ~ angle^2
        cv_error = self._cv.step(dt, position)  # type: ignore[union-attr]
        ca_error = self._ca.step(dt, position)  # type: ignore[union-attr]
        filter_error = self._filter.step(dt, orientation)  # type: ignore[union-attr]
        weight = 1.0 - math.exp(-dt / self.memory)
        scores = self._position_scores
        scores[0] += weight * (still_position - scores[0])
        scores[1] += weight * (cv_error - scores[1])
        scores[2] += weight * (ca_error - scores[2])
        scores = self._orientation_scores
        scores[0] += weight * (still_orientation - scores[0])
        scores[1] += weight * (filter_error - scores[1])
        self._t = t
        self._position, self._orientation = position, orientation
        if t - self._start >= self.memory:
            self._position_model = _simplest_within(self._position_scores, self.margin, self.position_noise)
            self._orientation_model = _simplest_within(self._orientation_scores, self.margin, self.orientation_noise)

    def predict(self, t: float) -> Pose:
        """The pose at t (s) from the chosen models."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        model = self._position_model
        if model == 0:
            position = self._position
        elif model == 1:
            position = self._cv.at(h)  # type: ignore[union-attr]
        else:
            position = self._ca.at(h)  # type: ignore[union-attr]
        orientation = self._filter.at(h) if self._orientation_model else self._orientation  # type: ignore[union-attr]
        return Pose(t, position, orientation)

    @property
    def choice(self) -> AutoChoice:
        """The models in use and the scores that chose them."""
        position = POSITION_MODELS[self._position_model]
        orientation = ORIENTATION_MODELS[self._orientation_model]
        if self._t is None:
            return AutoChoice(position, orientation, "no sample yet: no prediction")
        scored = self._t - self._start
        if scored < self.memory:
            return AutoChoice(
                position, orientation, f"warming up: {scored:.3g} s of {self.memory:g} s scored, no prediction yet"
            )
        position_rms = ", ".join(
            f"{name} {1e3 * math.sqrt(score):.3g} mm" for name, score in zip(POSITION_MODELS, self._position_scores)
        )
        orientation_rms = ", ".join(
            f"{name} {math.degrees(math.sqrt(score)):.3g} deg"
            for name, score in zip(ORIENTATION_MODELS, self._orientation_scores)
        )
        return AutoChoice(
            position,
            orientation,
            f"simplest within {100 * self.margin:g}% of the best RMS one-step error plus the tracker noise; "
            f"position: {position_rms}; orientation: {orientation_rms}",
        )
