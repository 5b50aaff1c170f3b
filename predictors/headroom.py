"""How far a linear predictor on `rls`'s features can go on a corpus: coefficients fitted offline on
all groups but one, scored on the one left out.

`rls` learns on the stream one coefficient per feature (the newest angular velocity w and the
differences of its moving averages, w - m1, m1 - m2, m2 - m3) shared by the three axes. Fitting
those coefficients by least squares on other people's recordings, with every future sample known,
and scoring them on the person left out, estimates what a better-fitted linear predictor on the same
features could gain there: this family's headroom, not a predictor (it needs the other people's
recordings, and it does not adapt to the one it is scored on). Three fits, per horizon:

* `shared`: one coefficient per feature, the same on every axis. This is what `rls` can represent,
  and it does not depend on the tracker's frame: turning every recording by one rotation changes
  nothing.
* `yaw/tilt`: one coefficient per feature for the part along a recording's own principal axis of
  turning (the axis of the angular velocity's largest variance over the whole recording, which is
  the vertical for a person turning their head), and one for the part across it. It weighs yaw
  apart from tilt without being told the tracker's frame: turning a recording changes nothing.
* `per axis`: a 3 x 3 matrix per feature, in the recordings' world frame. It can weigh every axis
  apart, so it is a bound only for trackers whose world frames agree (up the same axis).

Each anchor is a sample with a velocity: not the first after a start or a gap longer than
`max_gap`, and a sample older than the one before or less than `min_interval` after it (a repeated
time) is skipped. Its features are those `rls` has after taking it, from sensor times; its target
the turn from its orientation to the truth H later, over H (rad/s). A recording's score at H is the
RMS angle of the fit's error over constant velocity's (the newest velocity alone, as `slerp`), a
group's the geometric mean over its recordings, a corpus's the geometric mean over held-out groups.
In the fit every recording weighs the same within its group (its squared errors over constant
velocity's mean squared error there, over its anchors) and every group the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from predictors import quaternion
from predictors.cross_validation import geometric_mean
from predictors.extrapolators import MIN_INTERVAL
from predictors.params import MAX_GAP
from predictors.rls import TIME_CONSTANTS_S
from predictors.trace import Trace

FITS = ("shared", "yaw/tilt", "per axis")
FEATURES = 4  # w, w - m1, m1 - m2, m2 - m3
_RIDGE = 1e-9  # relative to the normal matrix's mean diagonal: keeps collinear features solvable


@dataclass(frozen=True)
class Anchors:
    """A recording's anchors: sensor times (N,), orientations (N, 4) and features (N, 4, 3), rad/s."""

    t: np.ndarray
    orientation: np.ndarray
    features: np.ndarray


def anchors_of(trace: Trace, min_interval: float = MIN_INTERVAL.default, max_gap: float = MAX_GAP.default) -> Anchors:
    """Every sample of the trace with a velocity, and `rls`'s features there (the module docstring
    gives the sample rules)."""
    decay_times = np.asarray(TIME_CONSTANTS_S)
    times, orientations, rows = [], [], []
    last_t, last_q, averages = None, None, None
    for t, q in zip(trace.t.tolist(), trace.orientation):
        dt = math.inf if last_t is None else t - last_t
        if dt < min_interval:
            continue
        if dt > max_gap:
            last_t, last_q, averages = t, q, None
            continue
        w = _turn(last_q, q) / dt
        averages = np.repeat(w[None], 3, 0) if averages is None else w + np.exp(-dt / decay_times)[:, None] * (averages - w)
        rows.append(np.stack([w, w - averages[0], averages[0] - averages[1], averages[1] - averages[2]]))
        times.append(t)
        orientations.append(q)
        last_t, last_q = t, q
    return Anchors(np.asarray(times, float), np.asarray(orientations, float).reshape(-1, 4), np.asarray(rows, float).reshape(-1, FEATURES, 3))


def targets(trace: Trace, anchors: Anchors, horizon_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The turn from each anchor's orientation to the truth `horizon_s` later, over the horizon
    (rad/s, world frame, the short way), and which anchors have that truth (their time plus the
    horizon inside the truth's span)."""
    target = anchors.t + horizon_s
    known = trace.covers(target)
    _, truth = trace.truth_at(target[known])
    return _turn(anchors.orientation[known], truth) / horizon_s, known


def _turn(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The world-frame rotation vector from a to b (`to_rotation_vector` takes the short way, so either sign of either)."""
    return quaternion.to_rotation_vector(quaternion.multiply(b, quaternion.conjugate(a)))


@dataclass(frozen=True)
class _Examples:
    """One recording's anchors at one horizon: features (N, 4, 3), targets (N, 3), constant
    velocity's mean squared error there, the recording's principal axis of turning (3,), and per
    fit its normal equations (the design's Gram matrix and its product with the targets) over the
    anchors and that error, so that every recording weighs the same (empty where it cannot: no
    anchors, or constant velocity exact)."""

    features: np.ndarray
    targets: np.ndarray
    baseline: float
    axis: np.ndarray
    equations: dict[str, tuple[np.ndarray, np.ndarray]]


def principal_axis(anchors: Anchors) -> np.ndarray:
    """The unit axis of the angular velocity's largest variance (about zero) over the anchors; its
    sign is arbitrary."""
    w = anchors.features[:, 0]
    _, vectors = np.linalg.eigh(w.T @ w)
    return vectors[:, -1]


def _design(x: np.ndarray, axis: np.ndarray, fit: str) -> np.ndarray:
    """Rows of the least-squares problem for features x (N, 4, 3): (3N, 4) for `shared` (axes
    stacked), (3N, 8) for `yaw/tilt` (the features along the axis, then across it), (N, 12) for
    `per axis`."""
    if fit == "per axis":
        return x.reshape(len(x), -1)
    if fit == "yaw/tilt":
        along = (x @ axis)[:, :, None] * axis
        x = np.concatenate([along, x - along], axis=1)
    return x.transpose(0, 2, 1).reshape(len(x) * 3, -1)


def _examples(trace: Trace, anchors: Anchors, axis: np.ndarray, horizon_s: float) -> _Examples:
    y, known = targets(trace, anchors, horizon_s)
    x = anchors.features[known]
    baseline = float(np.mean(np.sum((x[:, 0] - y) ** 2, axis=1))) if len(y) else 0.0
    equations = {}
    if baseline > 0.0:
        for fit in FITS:
            design, scale = _design(x, axis, fit), 1.0 / (len(y) * baseline)
            equations[fit] = (scale * design.T @ design, scale * design.T @ (y if fit == "per axis" else y.reshape(-1, 1)))
    return _Examples(x, y, baseline, axis, equations)


def _fit(training: Sequence[Sequence[_Examples]], fit: str) -> np.ndarray | None:
    """Least-squares coefficients over groups of recordings' examples, each group and, within it,
    each recording weighing the same: (4, 1) for `shared`, (8, 1) for `yaw/tilt`, (12, 3) for
    `per axis`; None where no training recording turns."""
    terms = []
    for group in training:
        kept = [e.equations[fit] for e in group if e.equations]
        terms += [(normal / len(kept), cross / len(kept)) for normal, cross in kept]
    if not terms:
        return None
    normal, cross = sum(n for n, _ in terms), sum(c for _, c in terms)
    scale = np.trace(normal) / len(normal)
    if not scale > 0.0:
        return None
    return np.linalg.solve(normal + _RIDGE * scale * np.eye(len(normal)), cross)


def _ratio(examples: _Examples, coefficients: np.ndarray | None, fit: str) -> float:
    """RMS angle of the fit's error over constant velocity's, on one recording at one horizon (NaN
    where either is undefined)."""
    if coefficients is None or not examples.equations:
        return math.nan
    predicted = (_design(examples.features, examples.axis, fit) @ coefficients).reshape(examples.targets.shape)
    return math.sqrt(float(np.mean(np.sum((predicted - examples.targets) ** 2, axis=1))) / examples.baseline)


@dataclass(frozen=True)
class HeadroomFold:
    """One group held out: its recordings, and per fit and horizon (ms) the geometric mean over them
    of the ratio of the fit made on the other groups."""

    group: str
    recordings: tuple[str, ...]
    ratios: dict[str, dict[float, float]]


def headroom(traces: Mapping[str, Trace], groups: Mapping[str, Sequence[str]], horizons_ms: Sequence[float]) -> list[HeadroomFold]:
    """For every group: each of `FITS` made on all the other groups, scored on that one (an empty list
    for fewer than two groups)."""
    if len(groups) < 2:
        return []
    anchors = {name: anchors_of(traces[name]) for members in groups.values() for name in members}
    axes = {name: principal_axis(a) for name, a in anchors.items()}
    ratios: dict[str, dict[str, dict[float, float]]] = {g: {fit: {} for fit in FITS} for g in groups}
    for h in horizons_ms:
        examples = {name: _examples(traces[name], a, axes[name], h / 1e3) for name, a in anchors.items()}
        for held, members in groups.items():
            training = [[examples[n] for n in others] for g, others in groups.items() if g != held]
            for fit in FITS:
                coefficients = _fit(training, fit)
                ratios[held][fit][h] = geometric_mean([_ratio(examples[n], coefficients, fit) for n in members])
    return [HeadroomFold(g, tuple(members), ratios[g]) for g, members in groups.items()]


def corpus_headroom(folds: Sequence[HeadroomFold], fit: str, horizon_ms: float) -> float:
    """The geometric mean over held-out groups of one fit's ratio at one horizon."""
    return geometric_mean([fold.ratios[fit][horizon_ms] for fold in folds])
