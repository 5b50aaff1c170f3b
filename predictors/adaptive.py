"""`adaptive`: learns, on the stream it is fed, which motion model predicts best at each horizon.

No parameter is tuned to a tracker or a person. The predictor runs several candidate estimates of
the motion side by side (`predictors.smoothers`: the velocity through the last two samples, and
Kalman smoothers of 25, 10 and 4 Hz bandwidth), and keeps scoring their predictions at horizons of
10, 20, 40, 80 and 160 ms against the samples that arrive later (`predictors.horizon_scores`).
At each horizon it learns a gain on the two-sample velocity from those errors, and trusts the
model whose realised errors there have been smallest: at the shortest horizon constant velocity
from the last two samples (slerp extrapolation) until another has beaten it by `margin`, at each
longer one the shorter one's model until another has beaten that. So a clean tracker gets a model
that follows it, a noisy one a smoother, jittery micro-movements a damped velocity, each horizon
its own; and the answer changes as the stream does, with a memory of `memory` seconds.

`predict(t)` answers any horizon h = t - (newest sample time): between two scored horizons it
blends their predictions, weighted by where h lies between them on a log scale; below 10 ms it uses
the 10 ms choice, above 160 ms the 160 ms one; for the first second of scores, the least smoothing
Kalman smoother (`predictors.horizon_scores.COLD_START`). Everything is driven by timestamps: the
scores are per second of motion, each horizon is scored at most once per horizon, the two longest
unscored first (`SCORES_PER_SAMPLE`, so the cost per sample stays bounded at any rate), and the
smoothers' bandwidths are in Hz.

Sample rules: samples are taken in sensor-time order; an older sample than the newest is dropped;
one less than `min_interval` after the newest replaces it (a duplicate: the smoothers take it as a
second measurement and the two-sample velocity is taken from the sample before); a gap longer than
`max_gap` restarts the estimates from the next sample but keeps what was learnt about the stream.

`state` reports what it trusts at each horizon, with the learnt gains, the errors scored, and the
tracker noise it measured: from the second differences of the samples, whose lag-one covariance is
-4/6 of their variance for white noise and close to their variance for smooth motion, so that
sigma^2 = (<d_k.d_k> - <d_k.d_k-1>) / 10 per axis (only reported; the choice needs no noise level).
"""

from __future__ import annotations

import math
from bisect import bisect_left
from dataclasses import dataclass
from math import exp, log, sqrt
from typing import Any, ClassVar, Sequence

from predictors import scalar_quaternion as squat
from predictors.checks import horizon, read_sample
from predictors.extrapolators import MIN_INTERVAL
from predictors.horizon_scores import BASELINE, COLD_START, MODEL_NAMES, MODELS, Choice, HorizonScore
from predictors.params import MAX_GAP, MAX_HORIZON, OPEN_UNIT, Param, ParamSet, Range, declare_params
from predictors.pose import Pose, PoseSample
from predictors.smoothers import Estimate, Smoothers, two_sample

HORIZONS_S = (0.01, 0.02, 0.04, 0.08, 0.16)
SCORES_PER_SAMPLE = 2
SCORE_EVERY = 1.0  # a horizon is scored at most once per this many horizons
_LOG_HORIZONS = tuple(log(h) for h in HORIZONS_S)
_SCORE_GAPS = tuple(SCORE_EVERY * h for h in HORIZONS_S)


def due_horizons(lasts: Sequence[float], t: float, at_most: int) -> list[tuple[float, int]]:
    """The (at most `at_most`) horizons longest unscored at `t`, each due once per `SCORE_EVERY`
    horizons since `lasts[k]`, when it was last scored: (last scored, index of the horizon)."""
    due = [(last, k) for k, last in enumerate(lasts) if t - last >= _SCORE_GAPS[k]]
    if len(due) > 1:  # most samples have one due or none: nothing to sort
        due.sort()
    del due[at_most:]
    return due


def turn_at(
    q_anchor: squat.Quaternion, q_now: squat.Quaternion, r: tuple[float, float, float], back: float
) -> tuple[float, float, float]:
    """The turn (a rotation vector) from the anchor's orientation to the truth at a target `back` of
    the way from the newest sample towards the one before, the newest having turned by r from it:
    the turn to the newest less that part of the last step, r + r x turn / 2 to second order."""
    a0, a1, a2 = squat.rotation_vector_between(q_anchor, q_now)
    r0, r1, r2 = r
    return (
        a0 - back * (r0 + 0.5 * (r1 * a2 - r2 * a1)),
        a1 - back * (r1 + 0.5 * (r2 * a0 - r0 * a2)),
        a2 - back * (r2 + 0.5 * (r0 * a1 - r1 * a0)),
    )


def overtaken(anchors: Sequence[tuple[Any, ...]], i: int, ahead: float, t: float) -> int:
    """From anchor `i` on, the latest anchor before the newest (each a tuple whose first value is
    its time) whose prediction `ahead` seconds on the time `t` has passed."""
    newest = len(anchors) - 1
    while i + 1 < newest and anchors[i + 1][0] + ahead <= t:
        i += 1
    return i
# History kept beyond the oldest anchor still needed, before the list is trimmed (amortised).
_TRIM_AFTER = 256

MEMORY = Param(
    "memory", 10.0, "seconds",
    "Time constant of the scores, the learnt gains and the noise estimate: how long what the stream "
    "showed counts.",
    Range(0.0, 3600.0, includes_high=True),
)
MARGIN = Param(
    "margin", 0.05, "",
    "A fraction: another model is trusted at a horizon only while its scored squared error there is "
    "below (1 - margin) times that of the model it would keep (constant velocity at the shortest "
    "horizon, the next shorter horizon's choice at the others).",
    OPEN_UNIT,
)
GAIN_PRIOR = Param(
    "gain_prior", 2.0, "seconds",
    "The learnt velocity gains start at 1 and count as this many seconds of evidence for 1.",
    Range(0.0, 3600.0, includes_high=True),
)

# (t_sensor, position, orientation, the candidates' estimates) of a sample.
_Anchor = tuple[float, tuple[float, float, float], squat.Quaternion, tuple[Estimate, ...]]


@dataclass(frozen=True)
class HorizonChoice:
    """What `adaptive` trusts at one horizon: the model and its velocity gain for orientation and
    for position, the seconds scored, and each model's RMS error there (deg, mm; `MODEL_NAMES` order)."""

    horizon_ms: float
    orientation_model: str
    orientation_gain: float
    position_model: str
    position_gain: float
    scored_s: float
    orientation_rms_deg: tuple[float, ...]
    position_rms_mm: tuple[float, ...]


@dataclass(frozen=True)
class AdaptiveState:
    """`adaptive`'s state: its choice per horizon, the tracker noise it measured (per axis) and the
    mean sample interval."""

    horizons: tuple[HorizonChoice, ...]
    orientation_noise_deg: float
    position_noise_mm: float
    sample_interval_ms: float


@declare_params(MEMORY, MARGIN, GAIN_PRIOR, MIN_INTERVAL, MAX_GAP, MAX_HORIZON)
class Adaptive:
    """Trusts, per horizon, the candidate model whose realised errors on this stream have been
    smallest (`adaptive`); see `predictors.adaptive`."""

    name = "adaptive"
    params: ClassVar[ParamSet]

    def __init__(self, **values: Any) -> None:
        """Parameters as keyword arguments, each then an attribute (the class docstring lists them)."""
        self.params.assign(self, values)
        self.reset()

    def reset(self) -> None:
        """Forget every sample and everything learnt."""
        self._scores = [HorizonScore(h) for h in HORIZONS_S]
        self._trusted: list[Choice] = [COLD_START] * len(HORIZONS_S)
        self._kept: list[tuple[int, int] | None] = [None] * len(HORIZONS_S)  # the models each choice kept by default
        self._noise = [0.0, 0.0, 0.0]  # EW weight (s), sums of d.d - d.d_prev: orientation, position
        self._t: float | None = None
        self._restart()

    def _restart(self) -> None:
        self._last_scored = [-math.inf] * len(HORIZONS_S)
        self._smoothers = Smoothers()
        self._history: list[_Anchor] = []
        self._anchors = [0] * len(HORIZONS_S)
        self._older: tuple[float, tuple[float, float, float], squat.Quaternion] | None = None
        self._steps: tuple[float, tuple[float, float, float], tuple[float, float, float]] | None = None
        self._position_moved = False
        # The last second differences of the orientation and the position.
        self._second_differences: tuple[float, float, float, float, float, float] | None = None

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample (the module docstring gives the order rules)."""
        t, position, orientation = read_sample(sample, self.name)
        last = self._t
        if last is None or t - last > self.max_gap:
            self._restart()
            self._t, self._position, self._orientation = t, position, orientation
            self._history.append((t, position, orientation, self._smoothers.estimates))
            return
        dt = t - last
        if dt < 0.0:
            return
        r = squat.rotation_vector_between(self._orientation, orientation)
        p = self._position
        (x, y, z), (x0, y0, z0) = position, p
        rp = (x - x0, y - y0, z - z0)
        if not self._position_moved and rp != (0.0, 0.0, 0.0):
            self._position_moved = True
        if dt < self.min_interval:
            self._replace_newest(t, position, orientation, r, rp)
            return
        self._older = (last, p, self._orientation)
        self._smoothers.advance(dt, r, rp, two_sample(dt, r, rp))
        self._note_noise(dt, r, rp)
        self._t, self._position, self._orientation = t, position, orientation
        self._history.append((t, position, orientation, self._smoothers.estimates))
        self._score(t, r)

    def _replace_newest(self, t: float, position: tuple[float, float, float], orientation: squat.Quaternion,
                        r: tuple[float, float, float], rp: tuple[float, float, float]) -> None:
        older = self._older
        if older is None:
            estimate = self._smoothers.estimates[0]
        else:
            t0, p0, q0 = older
            dt = t - t0
            w = squat.rotation_vector_between(q0, orientation)
            estimate = two_sample(dt, w, (position[0] - p0[0], position[1] - p0[1], position[2] - p0[2]))
        self._smoothers.advance(0.0, r, rp, estimate)
        self._t, self._position, self._orientation = t, position, orientation
        self._history[-1] = (t, position, orientation, self._smoothers.estimates)

    def _note_noise(self, dt: float, r: tuple[float, float, float], rp: tuple[float, float, float]) -> None:
        """Second differences of the steps (rescaled to this step's length), their squares and
        lag-one products, as exponentially weighted sums."""
        steps = self._steps
        self._steps = (dt, r, rp)
        if steps is None:
            return
        dt_before, (c0, c1, c2), (e0, e1, e2) = steps
        scale = dt / dt_before
        r0, r1, r2 = r
        s0, s1, s2 = rp
        d0, d1, d2 = r0 - scale * c0, r1 - scale * c1, r2 - scale * c2
        p0, p1, p2 = s0 - scale * e0, s1 - scale * e1, s2 - scale * e2
        previous = self._second_differences
        self._second_differences = (d0, d1, d2, p0, p1, p2)
        if previous is None:
            return
        b0, b1, b2, q0, q1, q2 = previous
        decay = exp(-dt / self.memory)
        noise = self._noise
        noise[0] = decay * noise[0] + dt
        noise[1] = decay * noise[1] + dt * (d0 * d0 + d1 * d1 + d2 * d2 - d0 * b0 - d1 * b1 - d2 * b2)
        noise[2] = decay * noise[2] + dt * (p0 * p0 + p1 * p1 + p2 * p2 - p0 * q0 - p1 * q1 - p2 * q2)

    def _score(self, t: float, r: tuple[float, float, float]) -> None:
        """Score the (at most `SCORES_PER_SAMPLE`) horizons longest unscored, each at most once per
        `SCORE_EVERY` horizons, whose predictions from an earlier sample the newest one (which
        turned by r from the one before) has just overtaken. Each score weighs the seconds since
        its horizon was last scored."""
        lasts = self._last_scored
        due = due_horizons(lasts, t, SCORES_PER_SAMPLE)
        if not due:
            return  # no anchor moved, so none is past the trimming point
        history = self._history
        t_before, p_before, _, _ = history[-2]
        (n0, n1, n2), q_now = self._position, self._orientation
        b0, b1, b2 = n0 - p_before[0], n1 - p_before[1], n2 - p_before[2]
        position_moved = self._position_moved
        anchors, scores = self._anchors, self._scores
        max_gap, memory, gain_prior = self.max_gap, self.memory, self.gain_prior
        scored = []
        for last, k in due:
            ahead = HORIZONS_S[k]
            anchors[k] = i = overtaken(history, anchors[k], ahead, t)
            t_anchor, p_anchor, q_anchor, estimates = history[i]
            target = t_anchor + ahead
            if not t_before < target <= t:
                continue
            # The truth at the target, between the sample before and the newest.
            back = (t - target) / (t - t_before)
            if position_moved:
                moved = (n0 - back * b0 - p_anchor[0], n1 - back * b1 - p_anchor[1], n2 - back * b2 - p_anchor[2])
            else:
                moved = None
            if last > -math.inf:
                weight = t - last
                if weight > max_gap:
                    weight = max_gap
            else:
                weight = t - t_before
                if weight > ahead:
                    weight = ahead
            lasts[k] = t
            scores[k].learn(turn_at(q_anchor, q_now, r, back), moved, estimates, weight, memory, gain_prior)
            scored.append(k)
        if scored:
            self._trust(scored)
        oldest = min(anchors)
        if oldest > _TRIM_AFTER:
            del history[:oldest]
            self._anchors = [i - oldest for i in anchors]

    def _trust(self, scored: list[int]) -> None:
        """Each horizon's choice, shortest first: a ready horizon keeps the next shorter one's
        model (constant velocity for the shortest) unless another beats it there by `margin`; a
        horizon not yet ready takes the next shorter one's choice; before any is ready,
        `COLD_START`. A choice is made again only where the horizon was just `scored` or the model
        it would keep changed."""
        trusted, kept = self._trusted, self._kept
        choice: Choice | None = None
        for k, score in enumerate(self._scores):
            if score.ready:
                default = choice or BASELINE
                (model, _), (position_model, _) = default
                if k in scored or kept[k] != (model, position_model):
                    kept[k] = (model, position_model)
                    trusted[k] = score.choose(default, self.gain_prior, self.margin, self._position_moved)
                choice = trusted[k]
            else:
                trusted[k] = choice or COLD_START

    def predict(self, t: float) -> Pose:
        """The pose at t (s): each part blended from the models trusted at the horizons either side
        of t - (newest sample time), at most max_horizon seconds either way."""
        t, h = horizon(t, self._t, self.max_horizon, self.name)
        blend = self._blend(h)
        estimates = self._smoothers.estimates
        d0 = d1 = d2 = 0.0
        for ((model, gain), _), share in blend:
            a0, a1, a2, w0, w1, w2 = estimates[MODELS[model]][0]
            # The turn gain h w after the offset a: a + u + u x a / 2 to second order, u = gain h w.
            reach = gain * h
            u0, u1, u2 = reach * w0, reach * w1, reach * w2
            d0 += share * (a0 + u0 + 0.5 * (u1 * a2 - u2 * a1))
            d1 += share * (a1 + u1 + 0.5 * (u2 * a0 - u0 * a2))
            d2 += share * (a2 + u2 + 0.5 * (u0 * a1 - u1 * a0))
        return Pose(t, self._position_after(h, blend), squat.rotated_by(d0, d1, d2, self._orientation))

    def position_at(self, t: float) -> tuple[float, float, float]:
        """The position `predict(t)` gives, without making the pose or the orientation (`split` and
        `rls` take only this part)."""
        _, h = horizon(t, self._t, self.max_horizon, self.name)
        return self._position_after(h, self._blend(h))

    def _blend(self, h: float) -> tuple[tuple[Choice, float], ...]:
        """The choices trusted at the scored horizons either side of h (s), each with its share."""
        trusted = self._trusted
        if h <= HORIZONS_S[0]:
            return ((trusted[0], 1.0),)
        if h >= HORIZONS_S[-1]:
            return ((trusted[-1], 1.0),)
        k = bisect_left(HORIZONS_S, h) - 1  # HORIZONS_S[k] < h <= HORIZONS_S[k + 1]
        u = (log(h) - _LOG_HORIZONS[k]) / (_LOG_HORIZONS[k + 1] - _LOG_HORIZONS[k])
        return ((trusted[k], 1.0 - u), (trusted[k + 1], u))

    def _position_after(self, h: float, blend: tuple[tuple[Choice, float], ...]) -> tuple[float, float, float]:
        """The position h seconds after the newest sample, from the position models in `blend`."""
        estimates = self._smoothers.estimates
        m0 = m1 = m2 = 0.0
        for (_, (model, gain)), share in blend:
            a0, a1, a2, w0, w1, w2 = estimates[MODELS[model]][1]
            reach = share * gain * h
            m0 += share * a0 + reach * w0
            m1 += share * a1 + reach * w1
            m2 += share * a2 + reach * w2
        p = self._position
        return (p[0] + m0, p[1] + m1, p[2] + m2)

    @property
    def state(self) -> AdaptiveState:
        """What it trusts per horizon, with the learnt gains and scored errors, and the noise measured."""
        horizons = []
        for score, trusted in zip(self._scores, self._trusted):
            (model, gain), (position_model, position_gain) = trusted
            orientation_rms, position_rms = score.rms_errors()
            horizons.append(HorizonChoice(
                1e3 * score.horizon, MODEL_NAMES[model], gain, MODEL_NAMES[position_model], position_gain,
                score.scored, tuple(math.degrees(e) for e in orientation_rms), tuple(1e3 * e for e in position_rms),
            ))
        weight, turning, moving = self._noise
        per_axis = 1.0 / (30.0 * weight) if weight > 0.0 else 0.0
        return AdaptiveState(
            tuple(horizons),
            math.degrees(sqrt(max(0.0, turning * per_axis))),
            1e3 * sqrt(max(0.0, moving * per_axis)),
            1e3 * self._smoothers.interval,
        )
