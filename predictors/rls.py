"""`rls`: orientation from a linear predictor learnt on the stream by recursive least squares.

At each sample the features are the newest angular velocity w1 (the rotation vector from the
sample before to the newest, over their interval; world frame, the short way) and its last
`history` - 1 changes, w1 - w2, w2 - w3, ... At each of `HORIZONS_S` (those of `adaptive`) the
turn H seconds after the newest sample is predicted as

    H (c0 w1 + c1 (w1 - w2) + c2 (w2 - w3) + ...)

with one coefficient per feature shared by the three axes, so the prediction turns with the head
(the same in any frame). Constant velocity is c = (1, 0, 0, ...). Nothing is fitted offline: the
coefficients start there and are learnt on the stream itself. Each prediction's truth becomes known
once the tracker has passed the time it was made for, as `adaptive` scores its horizons (its
schedule, with one horizon per sample, `SCORES_PER_SAMPLE`, to bound the cost: each horizon at most
once per horizon, the longest unscored first, each score weighted by the seconds since that horizon
was last scored); then the horizon's least-squares
statistics, exponentially weighted over `memory` seconds, take the anchor's features and the
turn that followed, and its coefficients take one Gauss-Seidel sweep towards their solution:

    c = (A + p D)^-1 (b + p D e0),   A = <sum over axes of f_i f_j>,  b = <f_i . y / H>,

where D is A's diagonal and p = `prior` / (the seconds scored): `prior` seconds of evidence for
constant velocity, which also keeps the system solvable when the features are collinear (a
turn at constant velocity has no changes). Weighting by seconds rather than samples makes the
memory and the prior mean the same at 30 Hz and at 1 kHz; the features themselves span
`history` samples, so what they see of the motion depends on the rate.

A horizon uses its learnt coefficients only once it has been scored for `MIN_SCORED` seconds and
its realised squared error (each prediction scored with the coefficients it was made with) is
below (1 - `margin`) times that of constant velocity at the same anchors; otherwise constant
velocity. `predict(t)` blends the coefficients of the horizons either side of h on a log scale,
as `adaptive` blends its choices. Position is `adaptive`'s, as in `split`.

Sample rules are `adaptive`'s: an older sample than the newest is dropped; one less than
`min_interval` after it replaces it (the velocity taken from the sample before); a gap longer than
`max_gap` restarts the features from the next sample but keeps what was learnt; a bad sample is
refused with the state unchanged.
"""

from __future__ import annotations

import math
from math import exp, log
from operator import mul
from typing import Any, ClassVar

from predictors import scalar_quaternion as squat
from predictors.adaptive import GAIN_PRIOR, HORIZONS_S, MARGIN, MEMORY, Adaptive, due_horizons, overtaken, turn_at
from predictors.checks import horizon, read_sample
from predictors.errors import PredictorError
from predictors.extrapolators import MIN_INTERVAL
from predictors.horizon_scores import MIN_SCORED
from predictors.params import MAX_GAP, MAX_HORIZON, Param, ParamSet, Range, declare_params
from predictors.pose import Pose, PoseSample

Vector = tuple[float, float, float]
_LOG_HORIZONS = tuple(log(h) for h in HORIZONS_S)
_TRIM_AFTER = 256
SCORES_PER_SAMPLE = 1  # horizons learnt from per sample: adaptive's two cost a third more here for the same errors
# A floor on the prior's diagonal, relative to A's trace: keeps the solve defined on a stream with
# no changes at all (constant velocity, rest).
_FLOOR = 1e-9

HISTORY = Param(
    "history", 6.0, "samples",
    "A whole number: the features are the newest angular velocity and its changes over this many "
    "samples in all (1: constant velocity).",
    Range(1.0, 8.0, includes_low=True, includes_high=True),
)
PRIOR = Param(
    "prior", 0.25, "seconds",
    "The coefficients start at constant velocity's and count as this many seconds of evidence for it.",
    Range(0.0, 3600.0, includes_high=True),
)
RLS_MARGIN = Param(
    "margin", 0.02, "",
    "A fraction: the learnt coefficients are used at a horizon only while their scored squared error "
    "there is below (1 - margin) times constant velocity's.",
    MARGIN.range,
)
_ADAPTIVE = ("min_interval", "max_gap", "max_horizon")


class _Horizon:
    """The exponentially weighted statistics and coefficients of one horizon (s), for n features."""

    __slots__ = ("horizon", "scored", "gram", "cross", "coefficients", "errors", "trusted", "baseline", "used")

    def __init__(self, horizon: float, n: int) -> None:
        self.horizon = horizon
        self.scored = 0.0
        self.gram = [[0.0] * n for _ in range(n)]  # rows of the symmetric A
        self.cross = [0.0] * n
        self.baseline = [1.0] + [0.0] * (n - 1)  # constant velocity's coefficients
        self.coefficients = self.used = self.baseline
        self.errors = [0.0, 0.0]  # squared errors: learnt coefficients, constant velocity
        self.trusted = False


@declare_params(HISTORY, MEMORY, PRIOR, RLS_MARGIN, GAIN_PRIOR, MIN_INTERVAL, MAX_GAP, MAX_HORIZON)
class RecursiveLeastSquares:
    """Orientation from coefficients on the recent angular velocities learnt per horizon on the
    stream, position from `adaptive` (`rls`); see `predictors.rls`."""

    name = "rls"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        if self.history != int(self.history):
            raise PredictorError(f"{self.name}: history must be a whole number of samples, got {self.history!r}")
        self._n = int(self.history)
        adaptive = {k: getattr(self, k) for k in _ADAPTIVE}
        self._position = Adaptive(memory=self.memory, gain_prior=self.gain_prior, **adaptive)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and everything learnt."""
        self._position.reset()
        self._horizons = [_Horizon(h, self._n) for h in HORIZONS_S]
        self._t: float | None = None
        self._restart()

    def _restart(self) -> None:
        self._last_scored = [-math.inf] * len(HORIZONS_S)
        self._velocities: list[Vector] = []  # newest first, at most `history`
        self._older: tuple[float, squat.Quaternion] | None = None
        # (t_sensor, orientation, features or None before `history` velocities) per sample
        self._anchors: list[tuple[float, squat.Quaternion, tuple[Vector, ...] | None]] = []
        self._next = [0] * len(HORIZONS_S)

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample (the module docstring gives the order rules)."""
        t, _, orientation = read_sample(sample, self.name)
        self._position.update(sample)
        last = self._t
        if last is None or t - last > self.max_gap:
            self._restart()
            self._t, self._orientation = t, orientation
            self._anchors.append((t, orientation, None))
            return
        dt = t - last
        if dt < 0.0:
            return
        if dt < self.min_interval:
            older = self._older
            if older is not None:
                t0, q0 = older
                w = squat.rotation_vector_between(q0, orientation)
                self._velocities[0] = (w[0] / (t - t0), w[1] / (t - t0), w[2] / (t - t0))
            self._t, self._orientation = t, orientation
            self._anchors[-1] = (t, orientation, self._features())
            return
        r = squat.rotation_vector_between(self._orientation, orientation)
        self._older = (last, self._orientation)
        velocities = self._velocities
        velocities.insert(0, (r[0] / dt, r[1] / dt, r[2] / dt))
        del velocities[self._n:]
        self._t, self._orientation = t, orientation
        self._anchors.append((t, orientation, self._features()))
        self._score(t, r)

    def _features(self) -> tuple[Vector, ...] | None:
        """The newest velocity and its successive changes, once `history` velocities are known."""
        v = self._velocities
        if len(v) < self._n:
            return None
        return (v[0], *((a[0] - b[0], a[1] - b[1], a[2] - b[2]) for a, b in zip(v, v[1:])))

    def _score(self, t: float, r: Vector) -> None:
        """Learn at the (at most `SCORES_PER_SAMPLE`) horizons longest unscored whose predictions
        from an earlier anchor the newest sample (which turned by r from the one before) has just
        overtaken; the truth between the two newest samples as `adaptive` takes it."""
        lasts = self._last_scored
        due = due_horizons(lasts, t, SCORES_PER_SAMPLE)
        anchors = self._anchors
        newest = len(anchors) - 1
        t_before = anchors[newest - 1][0]
        q_now = self._orientation
        for last, k in due:
            learnt = self._horizons[k]
            ahead = learnt.horizon
            self._next[k] = i = overtaken(anchors, self._next[k], ahead, t)
            t_anchor, q_anchor, features = anchors[i]
            target = t_anchor + ahead
            if features is None or not t_before < target <= t:
                continue
            turn = turn_at(q_anchor, q_now, r, (t - target) / (t - t_before))
            weight = min(t - last, self.max_gap) if last > -math.inf else min(t - t_before, ahead)
            lasts[k] = t
            self._learn(learnt, features, turn, weight)
        oldest = min(self._next)
        if oldest > _TRIM_AFTER:
            del anchors[:oldest]
            self._next = [i - oldest for i in self._next]

    def _learn(self, learnt: _Horizon, features: tuple[Vector, ...], turn: Vector, weight: float) -> None:
        """Score the horizon's prediction from `features` against the true `turn` (each with the
        coefficients it was made with), then add them to its statistics and sweep its coefficients."""
        n = self._n
        scale = 1.0 / learnt.horizon
        y0, y1, y2 = turn[0] * scale, turn[1] * scale, turn[2] * scale
        c = learnt.coefficients
        p0 = p1 = p2 = 0.0
        for ci, f in zip(c, features):
            p0 += ci * f[0]
            p1 += ci * f[1]
            p2 += ci * f[2]
        v = features[0]
        decay = exp(-weight / self.memory)
        errors = learnt.errors
        errors[0] = decay * errors[0] + weight * ((y0 - p0) ** 2 + (y1 - p1) ** 2 + (y2 - p2) ** 2)
        errors[1] = decay * errors[1] + weight * ((y0 - v[0]) ** 2 + (y1 - v[1]) ** 2 + (y2 - v[2]) ** 2)
        learnt.scored = learnt.scored * decay + weight
        cross = learnt.cross
        gram = learnt.gram
        for i, fi in enumerate(features):
            a0, a1, a2 = fi
            cross[i] = decay * cross[i] + weight * (a0 * y0 + a1 * y1 + a2 * y2)
            row = gram[i]
            for j in range(i, n):
                fj = features[j]
                row[j] = decay * row[j] + weight * (a0 * fj[0] + a1 * fj[1] + a2 * fj[2])
            for j in range(i):
                row[j] = gram[j][i]
        learnt.coefficients = _swept(gram, cross, c, self.prior / learnt.scored)
        learnt.trusted = learnt.scored >= MIN_SCORED and errors[0] < (1.0 - self.margin) * errors[1]
        learnt.used = learnt.coefficients if learnt.trusted else learnt.baseline

    def predict(self, t: float) -> Pose:
        """The pose at t (s): adaptive's position, the orientation turned by the blended learnt
        coefficients on the recent velocities, at most max_horizon seconds from the newest sample."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        position = self._position.position_at(t)
        velocities = self._velocities
        if not velocities:
            return Pose(t, position, self._orientation)
        features = self._anchors[-1][2]
        v = velocities[0]
        w0, w1, w2 = v
        if features is not None:
            w0 = w1 = w2 = 0.0
            for c, f in zip(self.coefficients_at(h), features):
                w0 += c * f[0]
                w1 += c * f[1]
                w2 += c * f[2]
        return Pose(t, position, squat.rotated_by(h * w0, h * w1, h * w2, self._orientation))

    def coefficients_at(self, h: float) -> list[float]:
        """The coefficients used at horizon h (s): those of the horizons either side, blended on a
        log scale, each constant velocity's where that horizon does not trust its own."""
        horizons = self._horizons
        if h <= HORIZONS_S[0]:
            return horizons[0].used
        if h >= HORIZONS_S[-1]:
            return horizons[-1].used
        k = 0
        while HORIZONS_S[k + 1] < h:
            k += 1
        u = (log(h) - _LOG_HORIZONS[k]) / (_LOG_HORIZONS[k + 1] - _LOG_HORIZONS[k])
        return [(1.0 - u) * a + u * b for a, b in zip(horizons[k].used, horizons[k + 1].used)]


def _swept(gram: list[list[float]], cross: list[float], start: list[float], prior: float) -> list[float]:
    """One Gauss-Seidel sweep, from `start`, towards the solution of (A + p D) c = b + p D e0 for
    the symmetric A (`gram`, its rows), b (`cross`) and p = `prior`, D = A's diagonal floored at
    `_FLOOR` times its trace. One sweep per score is the recursion: the statistics change little
    from one score to the next, and each sweep brings the coefficients closer to the solution of a
    symmetric positive definite system; constant velocity's coefficients where A is zero."""
    n = len(cross)
    trace = sum(gram[i][i] for i in range(n))
    if not trace > 0.0:
        return [1.0] + [0.0] * (n - 1)
    floor = _FLOOR * trace
    x = list(start)
    for i, row in enumerate(gram):
        a = row[i]
        d = a if a > floor else floor
        pivot = a + prior * d
        if pivot > 0.0:
            s = cross[i] - sum(map(mul, row, x)) + a * x[i]
            x[i] = (s + prior * d if i == 0 else s) / pivot
    return x
