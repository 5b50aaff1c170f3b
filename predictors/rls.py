"""`rls`: orientation from a linear predictor on the angular velocity and its moving averages,
learnt on the stream by recursive least squares.

At each sample, from the newest angular velocity w (the rotation vector from the sample before to
the newest, over their interval; world frame, the short way) and its exponential moving averages
m1, m2, m3 over the time constants `TIME_CONSTANTS_S` (1 / (2 pi F) for `adaptive`'s smoothers'
bandwidths F, 25, 10 and 4 Hz: a decade of smoothing, in seconds whatever the rate), the features
are w and the successive differences w - m1, m1 - m2, m2 - m3. At each of `HORIZONS_S` (those of
`adaptive`) the turn H seconds after the newest sample is predicted as

    H (c0 w + c1 (w - m1) + c2 (m1 - m2) + c3 (m2 - m3))

with one coefficient per feature shared by the three axes, so the prediction turns with the head
(the same in any frame). Constant velocity is c = (1, 0, 0, 0). The averages smooth a fast noisy
tracker; the differences carry the acceleration (an average lags the motion by about its time
constant) and, per horizon, the offset from the newest sample to a smoothed orientation (at a
steady rate, an average of the orientation is the newest sample less a multiple of the average
velocity over the same time constant). Nothing is fitted offline: the coefficients start at
constant velocity's and are learnt on the stream itself. Each prediction's truth becomes known once
the tracker has passed the time it was made for, as `adaptive` scores its horizons (its schedule,
with one horizon per sample, `SCORES_PER_SAMPLE`, to bound the cost: each horizon at most once per
horizon, the longest unscored first, each score weighted by the seconds since that horizon was
last scored); then the horizon's least-squares statistics, exponentially weighted over `memory`
seconds, take the anchor's features and the turn that followed, and its coefficients take one
Gauss-Seidel sweep towards their solution:

    c = (A + p D)^-1 (b + p D e0),   A = <sum over axes of f_i f_j>,  b = <f_i . y / H>,

where D is A's diagonal and p = `prior` / (the seconds scored): `prior` seconds of evidence for
constant velocity, which also keeps the system solvable when the features are collinear (at
constant velocity the differences vanish). Weighting by seconds rather than samples makes the
memory and the prior mean the same at 30 Hz and at 1 kHz. The prior is small: on a fast noisy
tracker w is mostly noise, and the prior keeps about p of its weight on it.

A horizon uses its learnt coefficients only once it has been scored for `MIN_SCORED` seconds and
its realised squared error (each prediction scored with the coefficients it had before its truth
was learnt from) is below (1 - `margin`) times that of constant velocity at the same anchors;
otherwise constant velocity, and before it has been scored that long the least smoothing average
m1 alone (as `adaptive` starts from its least smoothing smoother), which spares a fast noisy
tracker constant velocity's noise while nothing is known. A fit from features that have shown
almost nothing (the first scores at rest, the first of a motion after rest) can be wild, its
errors millions of times constant velocity's; while the coefficients are not in use, each score's
squared error counts at most `CLIP` times constant velocity's (this score's or its mean so far), so
such scores are a debt of seconds, not one that keeps the fit out of use for many memories. While
they are in use, every error counts in full, so a wild fit is dropped at its first score.
`predict(t)` blends the coefficients of the horizons either side of h on a log scale, as `adaptive`
blends its choices. Position is `adaptive`'s, as in `split`.

Sample rules are `adaptive`'s: an older sample than the newest is dropped; one less than
`min_interval` after it replaces it (the velocity taken from the sample before, the averages
taking it in place of the one replaced); a gap longer than `max_gap` restarts the averages from the
next velocity but keeps what was learnt; a bad sample is refused with the state unchanged.
"""

from __future__ import annotations

import math
from math import exp, log, pi
from typing import Any, ClassVar

from predictors import scalar_quaternion as squat
from predictors.adaptive import GAIN_PRIOR, HORIZONS_S, MARGIN, MEMORY, Adaptive, due_horizons, overtaken, turn_at
from predictors.checks import horizon, read_sample
from predictors.extrapolators import MIN_INTERVAL
from predictors.horizon_scores import MIN_SCORED
from predictors.params import MAX_GAP, MAX_HORIZON, Param, ParamSet, Range, declare_params
from predictors.pose import Pose, PoseSample
from predictors.smoothers import BANDWIDTHS_HZ

Vector = tuple[float, float, float]
# The averages' time constants, 1 / (2 pi F) for `adaptive`'s smoothers' bandwidths F (25, 10, 4 Hz);
# the arithmetic below is written out for these three.
_FAST, _MEDIUM, _SLOW = (1.0 / (2.0 * pi * f) for f in BANDWIDTHS_HZ)
TIME_CONSTANTS_S = (_FAST, _MEDIUM, _SLOW)
_BASELINE = (1.0, 0.0, 0.0, 0.0)  # constant velocity's coefficients
_COLD_START = (1.0, -1.0, 0.0, 0.0)  # the least smoothing average alone: w - (w - m1)
_LOG_HORIZONS = tuple(log(h) for h in HORIZONS_S)
_TRIM_AFTER = 256
SCORES_PER_SAMPLE = 1  # horizons learnt from per sample: adaptive's two cost a third more here for the same errors
# A floor on the prior's diagonal, relative to A's trace: keeps the solve defined on a stream with
# no changes at all (constant velocity, rest).
_FLOOR = 1e-9
CLIP = 10.0  # while not in use, a score's squared error counts at most this many times constant velocity's

PRIOR = Param(
    "prior", 0.05, "seconds",
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
    """The exponentially weighted statistics and coefficients of one horizon (s)."""

    __slots__ = ("horizon", "scored", "gram", "cross", "coefficients", "errors", "trusted", "used")

    def __init__(self, horizon: float) -> None:
        self.horizon = horizon
        self.scored = 0.0
        self.gram = [0.0] * 10  # A's upper triangle, row by row
        self.cross = [0.0] * 4
        self.coefficients: tuple[float, ...] = _BASELINE
        self.errors = [0.0, 0.0]  # squared errors: learnt coefficients, constant velocity
        self.trusted = False
        self.used: tuple[float, ...] = _COLD_START


@declare_params(MEMORY, PRIOR, RLS_MARGIN, GAIN_PRIOR, MIN_INTERVAL, MAX_GAP, MAX_HORIZON)
class RecursiveLeastSquares:
    """Orientation from coefficients on the angular velocity and its moving averages learnt per
    horizon on the stream, position from `adaptive` (`rls`, the default predictor); see `predictors.rls`."""

    name = "rls"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        adaptive = {k: getattr(self, k) for k in _ADAPTIVE}
        self._position = Adaptive(memory=self.memory, gain_prior=self.gain_prior, **adaptive)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and everything learnt."""
        self._position.reset()
        self._horizons = [_Horizon(h) for h in HORIZONS_S]
        self._t: float | None = None
        self._restart()

    def _restart(self) -> None:
        self._last_scored = [-math.inf] * len(HORIZONS_S)
        # The averages m1, m2, m3 (9 components; None before a velocity), the same before the newest
        # velocity was taken in, and the sample before the newest (t_sensor, orientation): what a
        # duplicate of the newest sample is taken from again.
        self._averages: tuple[float, ...] | None = None
        self._averages_before: tuple[float, ...] | None = None
        self._older: tuple[float, squat.Quaternion] | None = None
        # (t_sensor, orientation, the features' 12 components, or None before a velocity) per sample
        self._anchors: list[tuple[float, squat.Quaternion, tuple[float, ...] | None]] = []
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
                self._anchors[-1] = (t, orientation, self._take(t - t0, w, self._averages_before))
            else:
                self._anchors[-1] = (t, orientation, None)
            self._t, self._orientation = t, orientation
            return
        r = squat.rotation_vector_between(self._orientation, orientation)
        self._older = (last, self._orientation)
        self._averages_before = self._averages
        self._t, self._orientation = t, orientation
        self._anchors.append((t, orientation, self._take(dt, r, self._averages)))
        self._score(t, r)

    def _take(self, dt: float, r: Vector, before: tuple[float, ...] | None) -> tuple[float, ...]:
        """The velocity w of turning by r in dt s taken into the averages m1, m2, m3 (which start
        from it after a (re)start, else move towards it from `before`); the features w, w - m1,
        m1 - m2, m2 - m3, components flattened."""
        w0, w1, w2 = r[0] / dt, r[1] / dt, r[2] / dt
        if before is None:
            self._averages = (w0, w1, w2) * 3
            return (w0, w1, w2) + (0.0,) * 9
        g, h, k = exp(-dt / _FAST), exp(-dt / _MEDIUM), exp(-dt / _SLOW)  # the averages' weights on their past
        a0, a1, a2, b0, b1, b2, c0, c1, c2 = before
        a0, a1, a2 = w0 + g * (a0 - w0), w1 + g * (a1 - w1), w2 + g * (a2 - w2)
        b0, b1, b2 = w0 + h * (b0 - w0), w1 + h * (b1 - w1), w2 + h * (b2 - w2)
        c0, c1, c2 = w0 + k * (c0 - w0), w1 + k * (c1 - w1), w2 + k * (c2 - w2)
        self._averages = (a0, a1, a2, b0, b1, b2, c0, c1, c2)
        return (w0, w1, w2, w0 - a0, w1 - a1, w2 - a2, a0 - b0, a1 - b1, a2 - b2, b0 - c0, b1 - c1, b2 - c2)

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

    def _learn(self, learnt: _Horizon, f: tuple[float, ...], turn: Vector, weight: float) -> None:
        """Score the horizon's prediction from the features `f` against the true `turn`, and constant
        velocity's, with the coefficients from before this score, then add them to its statistics,
        sweep its coefficients and decide whether to use them. Written out for speed: this is most
        of what `rls` adds to `adaptive`'s cost."""
        scale = 1.0 / learnt.horizon
        y0, y1, y2 = turn[0] * scale, turn[1] * scale, turn[2] * scale
        a0, a1, a2, b0, b1, b2, c0, c1, c2, d0, d1, d2 = f
        k0, k1, k2, k3 = learnt.coefficients
        decay = exp(-weight / self.memory)
        learnt.scored = scored = learnt.scored * decay + weight
        errors = learnt.errors
        baseline = (y0 - a0) ** 2 + (y1 - a1) ** 2 + (y2 - a2) ** 2
        errors[1] = decay * errors[1] + weight * baseline
        error = (
            (y0 - k0 * a0 - k1 * b0 - k2 * c0 - k3 * d0) ** 2
            + (y1 - k0 * a1 - k1 * b1 - k2 * c1 - k3 * d1) ** 2
            + (y2 - k0 * a2 - k1 * b2 - k2 * c2 - k3 * d2) ** 2
        )
        if not learnt.trusted:
            mean = errors[1] / scored
            cap = CLIP * (baseline if baseline > mean else mean)
            error = error if error < cap else cap
        errors[0] = decay * errors[0] + weight * error
        x = learnt.cross
        x[0] = decay * x[0] + weight * (a0 * y0 + a1 * y1 + a2 * y2)
        x[1] = decay * x[1] + weight * (b0 * y0 + b1 * y1 + b2 * y2)
        x[2] = decay * x[2] + weight * (c0 * y0 + c1 * y1 + c2 * y2)
        x[3] = decay * x[3] + weight * (d0 * y0 + d1 * y1 + d2 * y2)
        g = learnt.gram
        g[0] = decay * g[0] + weight * (a0 * a0 + a1 * a1 + a2 * a2)
        g[1] = decay * g[1] + weight * (a0 * b0 + a1 * b1 + a2 * b2)
        g[2] = decay * g[2] + weight * (a0 * c0 + a1 * c1 + a2 * c2)
        g[3] = decay * g[3] + weight * (a0 * d0 + a1 * d1 + a2 * d2)
        g[4] = decay * g[4] + weight * (b0 * b0 + b1 * b1 + b2 * b2)
        g[5] = decay * g[5] + weight * (b0 * c0 + b1 * c1 + b2 * c2)
        g[6] = decay * g[6] + weight * (b0 * d0 + b1 * d1 + b2 * d2)
        g[7] = decay * g[7] + weight * (c0 * c0 + c1 * c1 + c2 * c2)
        g[8] = decay * g[8] + weight * (c0 * d0 + c1 * d1 + c2 * d2)
        g[9] = decay * g[9] + weight * (d0 * d0 + d1 * d1 + d2 * d2)
        learnt.coefficients = _swept(g, x, learnt.coefficients, self.prior / scored)
        learnt.trusted = scored >= MIN_SCORED and errors[0] < (1.0 - self.margin) * errors[1]
        learnt.used = learnt.coefficients if learnt.trusted else _BASELINE if scored >= MIN_SCORED else _COLD_START

    def predict(self, t: float) -> Pose:
        """The pose at t (s): adaptive's position, the orientation turned by the blended learnt
        coefficients on the features, at most max_horizon seconds from the newest sample."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        position = self._position.position_at(t)
        f = self._anchors[-1][2]
        if f is None:
            return Pose(t, position, self._orientation)
        a0, a1, a2, b0, b1, b2, c0, c1, c2, d0, d1, d2 = f
        k0, k1, k2, k3 = self.coefficients_at(h)
        w0 = k0 * a0 + k1 * b0 + k2 * c0 + k3 * d0
        w1 = k0 * a1 + k1 * b1 + k2 * c1 + k3 * d1
        w2 = k0 * a2 + k1 * b2 + k2 * c2 + k3 * d2
        return Pose(t, position, squat.rotated_by(h * w0, h * w1, h * w2, self._orientation))

    @property
    def learnt(self) -> tuple[tuple[float, tuple[float, ...], bool], ...]:
        """Per horizon of `HORIZONS_S`: (the horizon (s), its learnt coefficients, whether they are
        used there)."""
        return tuple((k.horizon, k.coefficients, k.trusted) for k in self._horizons)

    def coefficients_at(self, h: float) -> tuple[float, ...]:
        """The coefficients used at horizon h (s): those of the horizons either side, blended on a
        log scale, each constant velocity's where that horizon does not use its own (m1's before it
        has been scored for `MIN_SCORED` seconds)."""
        horizons = self._horizons
        if h <= HORIZONS_S[0]:
            return horizons[0].used
        if h >= HORIZONS_S[-1]:
            return horizons[-1].used
        k = 0
        while HORIZONS_S[k + 1] < h:
            k += 1
        u = (log(h) - _LOG_HORIZONS[k]) / (_LOG_HORIZONS[k + 1] - _LOG_HORIZONS[k])
        a0, a1, a2, a3 = horizons[k].used
        b0, b1, b2, b3 = horizons[k + 1].used
        v = 1.0 - u
        return v * a0 + u * b0, v * a1 + u * b1, v * a2 + u * b2, v * a3 + u * b3


def _swept(gram: list[float], cross: list[float], start: tuple[float, ...], prior: float) -> tuple[float, ...]:
    """One Gauss-Seidel sweep, from `start`, towards the solution of (A + p D) c = b + p D e0 for
    the symmetric 4 x 4 A (`gram`, its upper triangle row by row), b (`cross`) and p = `prior`,
    D = A's diagonal floored at `_FLOOR` times its trace. One sweep per score is the recursion: the
    statistics change little from one score to the next, and each sweep brings the coefficients
    closer to the solution of a symmetric positive definite system; constant velocity's
    coefficients where A is zero."""
    aa, ab, ac, ad, bb, bc, bd, cc, cd, dd = gram
    trace = aa + bb + cc + dd
    if not trace > 0.0:
        return _BASELINE
    floor = _FLOOR * trace
    pa = prior * (aa if aa > floor else floor)
    pb = prior * (bb if bb > floor else floor)
    pc = prior * (cc if cc > floor else floor)
    pd = prior * (dd if dd > floor else floor)
    _, x1, x2, x3 = start
    x0 = (cross[0] + pa - ab * x1 - ac * x2 - ad * x3) / (aa + pa)
    x1 = (cross[1] - ab * x0 - bc * x2 - bd * x3) / (bb + pb)
    x2 = (cross[2] - ac * x0 - bc * x1 - cd * x3) / (cc + pc)
    x3 = (cross[3] - ad * x0 - bd * x1 - cd * x2) / (dd + pd)
    return x0, x1, x2, x3
