"""What `adaptive` has learnt at one prediction horizon: each model's realised error there, the gain
on the two-sample velocity that would have made it smaller, and which model to trust.

A *model* predicts the displacement offset + g H velocity from the newest sample, H seconds ahead,
from one candidate estimate (`predictors.smoothers`) and a gain g on its velocity term. The models
(`MODEL_NAMES`): constant velocity from the last two samples with g = 1 (the baseline: slerp
extrapolation); the same velocity with its gain learnt here; and each Kalman smoother with g = 1.

Each prediction's error becomes known once the tracker has passed the time it was made for:
H seconds after an anchor sample, the truth there (the samples either side, interpolated) gives
every model's error at once. Per model, separately for orientation (rad) and position (m), the
scores keep exponentially weighted sums over `memory` seconds, each scored error weighted by the
seconds since the horizon was last scored, so that statistics are per second of motion whatever
the sample rate:

* the learnt gain: least squares of the true displacement y on the velocity term f = H velocity,
  shrunk towards 1 by `gain_prior` seconds of pseudo-data and kept in [0, `GAIN_MAX`]:
  g = (n <f.y> + n0 <f.f>) / ((n + n0) <f.f>). A gain below 1 damps a velocity that does not
  carry (micro-movements, a tracker that repeats samples), above 1 follows one that grows. Learnt
  on the two-sample velocity only: the smoothers' velocities are smooth already, and learning
  theirs too changed nothing on the stress streams but the cost;
* the error: the squared error of the model's prediction with the gain it had *before* this
  error was known (so the score is out of sample);
* the choice (`choose`): a default model, kept unless another's error is below (1 - `margin`)
  times its, then the one of least error. `adaptive` makes constant velocity the default at the
  shortest horizon and each horizon's choice the default of the next longer one, so a model is
  trusted only once it has shown an advantage on this stream, and a long horizon, whose errors
  come slowly and in bursts, follows the shorter ones unless its own errors disagree.

A horizon scored for less than `MIN_SCORED` seconds is not `ready`: `adaptive` takes the next
shorter ready horizon's choice, or, from a cold start, `COLD_START`: the least smoothing Kalman
smoother, which follows a clean tracker almost as constant velocity does and spares a noisy fast
one the velocity noise of two samples a millisecond apart. A second of evidence, not a few
samples: a stream that starts at rest shows every smoother to advantage until the head first
moves, and the first turn would find a lagging one trusted.
"""

from __future__ import annotations

from math import exp

from predictors.smoothers import NAMES, Estimate, Vector

GAIN_MAX = 1.5
MIN_SCORED = 1.0  # seconds of scored predictions before a horizon's own choice counts

# Each model: the index of its estimate in `predictors.smoothers.NAMES`. The baseline, then the
# two-sample velocity with a learnt gain (`LEARNT`), then every smoother as it is.
MODELS: tuple[int, ...] = (0, 0, *range(1, len(NAMES)))
MODEL_NAMES = ("constant-velocity", "two-sample, learnt gain", *NAMES[1:])
LEARNT = 1
# (model, index of its estimate) of the models that take a smoother as it is.
_SMOOTHED = tuple((model, MODELS[model]) for model in range(LEARNT + 1, len(MODELS)))
Choice = tuple[tuple[int, float], tuple[int, float]]  # (model, gain) for orientation, for position
BASELINE: Choice = ((0, 1.0), (0, 1.0))
COLD_START: Choice = ((2, 1.0), (2, 1.0))

# Per model and part: EW sums of |f|^2, f.y and the squared error (the weight, their common
# denominator, is `scored`).
_FF, _FY, _SSE = 0, 1, 2


class HorizonScore:
    """Scores and learnt gains at one horizon (s), and the choice they make."""

    __slots__ = ("horizon", "scored", "ready", "_orientation", "_position")

    def __init__(self, horizon: float) -> None:
        self.horizon = horizon
        self.scored = 0.0
        # Whether enough has been scored here for this horizon's own choice to count.
        self.ready = False
        self._orientation = [[0.0, 0.0, 0.0] for _ in MODELS]
        self._position = [[0.0, 0.0, 0.0] for _ in MODELS]

    def learn(self, truth: Vector, truth_position: Vector | None, anchor: tuple[Estimate, ...], weight: float,
              memory: float, gain_prior: float) -> None:
        """Score every model's prediction from the `anchor` estimates against the true turn (rad)
        and displacement (m) from the anchor sample, `horizon` seconds later; `weight` is the
        seconds this score stands for. A stream whose position has never moved passes None for the
        displacement: its position scores stay zero."""
        decay = exp(-weight / memory)
        self.scored = scored = self.scored * decay + weight
        self.ready = scored >= MIN_SCORED
        prior = gain_prior / scored
        _learn(self._orientation, 0, self.horizon, truth, anchor, weight, decay, prior)
        if truth_position is not None:
            _learn(self._position, 1, self.horizon, truth_position, anchor, weight, decay, prior)

    def choose(self, default: Choice, gain_prior: float, margin: float, position: bool = True) -> Choice:
        """The model to trust here for each part: `default`'s unless another's scored squared error
        is below (1 - margin) times its, then the one of least error; with its gain learnt here.
        Without `position` (a stream whose position never moved) position keeps the default."""
        prior = gain_prior / self.scored
        orientation = _choose(self._orientation, default[0][0], prior, margin)
        return orientation, _choose(self._position, default[1][0], prior, margin) if position else default[1]

    def rms_errors(self) -> tuple[list[float], list[float]]:
        """Each model's RMS error at this horizon (rad, m), as scored so far (NaN before any)."""
        scored = self.scored if self.scored > 0.0 else float("nan")
        return (
            [(stats[_SSE] / scored) ** 0.5 for stats in self._orientation],
            [(stats[_SSE] / scored) ** 0.5 for stats in self._position],
        )


def _gain(ff: float, fy: float, prior: float) -> float:
    """The least-squares gain fy / ff shrunk towards 1 by `prior` (pseudo-weight over weight), in
    [0, GAIN_MAX]."""
    if ff <= 0.0:
        return 1.0
    gain = (fy + prior * ff) / ((1.0 + prior) * ff)
    return 0.0 if gain < 0.0 else GAIN_MAX if gain > GAIN_MAX else gain


def _learn(stats: list[list[float]], part: int, h: float, truth: Vector, anchor: tuple[Estimate, ...],
           weight: float, decay: float, prior: float) -> None:
    """Score every model for one part (0 orientation, 1 position) and learn the two-sample gain.
    Written out for speed: this is most of `adaptive`'s cost."""
    t0, t1, t2 = truth
    # The baseline and the learnt-gain model share the two-sample estimate.
    a0, a1, a2, w0, w1, w2 = anchor[0][part]
    y0, y1, y2 = t0 - a0, t1 - a1, t2 - a2
    f0, f1, f2 = h * w0, h * w1, h * w2
    e0, e1, e2 = y0 - f0, y1 - f1, y2 - f2
    baseline = stats[0]
    baseline[_SSE] = baseline[_SSE] * decay + weight * (e0 * e0 + e1 * e1 + e2 * e2)
    learnt = stats[1]
    ff, fy, sse = learnt
    gain = _gain(ff, fy, prior)
    e0, e1, e2 = y0 - gain * f0, y1 - gain * f1, y2 - gain * f2
    learnt[_FF] = ff * decay + weight * (f0 * f0 + f1 * f1 + f2 * f2)
    learnt[_FY] = fy * decay + weight * (f0 * y0 + f1 * y1 + f2 * y2)
    learnt[_SSE] = sse * decay + weight * (e0 * e0 + e1 * e1 + e2 * e2)
    for model, estimate in _SMOOTHED:
        a0, a1, a2, w0, w1, w2 = anchor[estimate][part]
        e0, e1, e2 = t0 - a0 - h * w0, t1 - a1 - h * w1, t2 - a2 - h * w2
        smoothed = stats[model]
        smoothed[_SSE] = smoothed[_SSE] * decay + weight * (e0 * e0 + e1 * e1 + e2 * e2)


def _choose(stats: list[list[float]], default: int, prior: float, margin: float) -> tuple[int, float]:
    best, least = default, (1.0 - margin) * stats[default][_SSE]
    for model, learnt in enumerate(stats):
        if learnt[_SSE] < least:
            best, least = model, learnt[_SSE]
    if best != LEARNT:
        return best, 1.0
    learnt = stats[best]
    return best, _gain(learnt[_FF], learnt[_FY], prior)
