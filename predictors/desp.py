"""Double exponential smoothing prediction (`desp`), after LaViola (2003).

Per sample, with smoothing factor a in (0, 1), position p and orientation q:

    S1 <- a p + (1 - a) S1,              S2 <- a S1 + (1 - a) S2
    Q1 <- slerp(Q1, q, a),               Q2 <- slerp(Q2, Q1, a)

and the prediction tau samples ahead, k = a tau / (1 - a):

    p(tau) = (2 + k) S1 - (1 + k) S2 = S1 + (1 + k) (S1 - S2)
    q(tau) = slerp(Q2, Q1, 2 + k)

(the quaternion form is the linear one with a + u (b - a) read as slerp(a, b, u), taken the short
way, so sign flips between samples do no harm). Smoothing counts samples, not seconds, as in the
paper; the horizon is turned into samples with the tracker's sample interval, given as
`sample_interval` or estimated online as a running mean of the intervals seen.

Samples are taken in sensor-time order: an older sample than the newest is dropped; a sample at
the newest one's time replaces it (the step is redone with the later arrival); a gap longer than
`max_gap` restarts the smoothing from the new sample.
"""

from __future__ import annotations

from typing import Any, ClassVar

from predictors import scalar_quaternion as squat
from predictors.checks import horizon, read_sample
from predictors.params import LOGIT, MAX_GAP, MAX_HORIZON, OPEN_UNIT, Param, Range, ParamSet, declare_params
from predictors.pose import Pose, PoseSample

# Weight of the newest interval in the running mean of the sample interval (about 20 samples).
INTERVAL_RATE = 0.05

Vector = tuple[float, float, float]

POSITION_ALPHA = Param(
    "position_alpha", 0.5, "", "Smoothing factor for position; larger follows faster.",
    OPEN_UNIT, LOGIT, trainable=True, acts_on="position",
)
ORIENTATION_ALPHA = Param(
    "orientation_alpha", 0.5, "", "Smoothing factor for orientation; larger follows faster.",
    OPEN_UNIT, LOGIT, trainable=True, acts_on="orientation",
)
SAMPLE_INTERVAL = Param(
    "sample_interval", None, "seconds",
    "The tracker's sample interval, which turns a horizon into samples; None estimates it from the samples.",
    Range(0.0, 10.0, includes_high=True),
)


class _Smoothed:
    """The two smoothing stages of position and orientation after one sample (immutable)."""

    __slots__ = ("s1", "s2", "q1", "q2")

    def __init__(self, s1: Vector, s2: Vector, q1: squat.Quaternion, q2: squat.Quaternion) -> None:
        self.s1, self.s2, self.q1, self.q2 = s1, s2, q1, q2


@declare_params(POSITION_ALPHA, ORIENTATION_ALPHA, SAMPLE_INTERVAL, MAX_GAP, MAX_HORIZON)
class DoubleExponentialSmoothing:
    """LaViola's double exponential smoothing predictor (`desp`)."""

    name = "desp"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self.reset()

    def reset(self) -> None:
        """Forget every sample."""
        self._t: float | None = None
        self._state: _Smoothed | None = None
        self._before: _Smoothed | None = None  # the state before the newest sample, to redo it
        self._interval: float | None = self.sample_interval
        self._measured_interval: float | None = None

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample (see the module docstring for the order rules)."""
        t, position, orientation = read_sample(sample, self.name)
        last = self._t
        if last is None or t - last > self.max_gap:
            self._state = _Smoothed(position, position, orientation, orientation)
            self._before = None
            self._t = t
            return
        dt = t - last
        if dt < 0.0:
            return
        if dt == 0.0:
            if self._before is None:
                self._state = _Smoothed(position, position, orientation, orientation)
            else:
                self._state = self._smoothed(self._before, position, orientation)
            return
        self._note_interval(dt)
        self._before = self._state
        self._state = self._smoothed(self._state, position, orientation)  # type: ignore[arg-type]
        self._t = t

    def _note_interval(self, dt: float) -> None:
        measured = self._measured_interval
        measured = dt if measured is None else measured + INTERVAL_RATE * (dt - measured)
        self._measured_interval = measured
        if self.sample_interval is None:
            self._interval = measured

    def _smoothed(self, state: _Smoothed, p: Vector, q: squat.Quaternion) -> _Smoothed:
        a = self.position_alpha
        b = 1.0 - a
        (x1, y1, z1), (x2, y2, z2) = state.s1, state.s2
        x1, y1, z1 = a * p[0] + b * x1, a * p[1] + b * y1, a * p[2] + b * z1
        x2, y2, z2 = a * x1 + b * x2, a * y1 + b * y2, a * z1 + b * z2
        ao = self.orientation_alpha
        q1 = squat.slerp(state.q1, q, ao)
        q2 = squat.slerp(state.q2, q1, ao)
        return _Smoothed((x1, y1, z1), (x2, y2, z2), q1, q2)

    def predict(self, t: float) -> Pose:
        """The pose at t (s), extrapolated (t - newest sample time) / sample interval samples ahead."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        state: Any = self._state
        interval = self._interval
        tau = 0.0 if interval is None else h / interval
        a = self.position_alpha
        gain = 1.0 + a * tau / (1.0 - a)
        (x1, y1, z1), (x2, y2, z2) = state.s1, state.s2
        position = (x1 + gain * (x1 - x2), y1 + gain * (y1 - y2), z1 + gain * (z1 - z2))
        ao = self.orientation_alpha
        orientation = squat.slerp(state.q2, state.q1, 2.0 + ao * tau / (1.0 - ao))
        return Pose(t, position, orientation)
