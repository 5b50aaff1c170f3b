"""The headroom of linear predictors on `rls`'s features: fitted on the other groups, scored on the
one held out, against motion whose best linear prediction is known."""

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import Trace, make, quaternion
from predictors.headroom import FITS, anchors_of, corpus_headroom, headroom
from predictors.synthetic import head_motion

HORIZONS_MS = (20.0, 100.0)


def decaying_turn(name: str, axis, speed: float, decay: float = 3.0, rate_hz: float = 60.0, seconds: float = 3.0) -> Trace:
    """A turn about a fixed axis whose rate dies away as exp(-decay t): every later turn is a fixed
    multiple of the newest velocity, so a linear predictor on it can be exact."""
    t = np.arange(int(seconds * rate_hz) + 1) / rate_hz
    angle = speed / decay * (1.0 - np.exp(-decay * t))
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    orientation = quaternion.multiply(quaternion.from_rotation_vector(angle[:, None] * axis), [0.9, 0.1, -0.3, 0.2])
    return Trace.from_samples(name, t, np.zeros((len(t), 3)), quaternion.normalise(orientation))


def people(traces):
    return {trace.name: trace for trace in traces}, {trace.name: [trace.name] for trace in traces}


def noisy_heads(count=3, seed=0):
    return [head_motion(4.0, 90.0, seed=seed + k, name=f"p{k}").with_noise(0.0, math.radians(0.2), seed=seed + k) for k in range(count)]


def test_a_turn_dying_away_is_predicted_almost_exactly_by_a_fit_on_other_people():
    traces, groups = people([decaying_turn("a", (0, 1, 0), 2.0), decaying_turn("b", (1, 0, 0.3), 1.0),
                             decaying_turn("c", (0.2, 0.1, 1), 3.0)])  # fmt: skip
    folds = headroom(traces, groups, HORIZONS_MS)
    assert [f.group for f in folds] == ["a", "b", "c"]
    for fold in folds:
        # Constant velocity overshoots by about a sixth of the turn at 100 ms; the frame-free fits,
        # learnt on the other two, are off only by the averages' start-up.
        for fit in ("shared", "yaw/tilt"):
            assert fold.ratios[fit][100.0] < 0.02, (fold.group, fit)
    # A matrix per feature learnt on turns about two axes knows nothing of the third person's axis.
    assert folds[0].ratios["per axis"][100.0] > 1.0


def test_noise_on_a_head_is_smoothed_better_than_constant_velocity():
    traces, groups = people(noisy_heads())
    folds = headroom(traces, groups, HORIZONS_MS)
    assert 0.2 < corpus_headroom(folds, "shared", 20.0) < 0.8


def test_turning_every_recording_by_one_rotation_leaves_the_frame_free_fits_unchanged():
    turn = quaternion.from_rotation_vector([0.4, -1.1, 0.7])
    heads = noisy_heads()
    turned = [Trace.from_samples(h.name, h.t, h.position, quaternion.multiply(turn, h.orientation)) for h in heads]
    before = headroom(*people([Trace.from_samples(h.name, h.t, h.position, h.orientation) for h in heads]), HORIZONS_MS)
    after = headroom(*people(turned), HORIZONS_MS)
    for a, b in zip(before, after):
        for fit in ("shared", "yaw/tilt"):
            assert b.ratios[fit] == pytest.approx(a.ratios[fit], rel=1e-7)


def yaw_and_tilt(name: str, yaw_axis, tilt_axis, yaw_speed: float, tilt_speed: float) -> Trace:
    """A turn about `yaw_axis` dying away as exp(-t) and a tilt across it dying away as exp(-10 t)."""
    t = np.arange(181) / 60.0
    yaw, tilt = yaw_speed * (1.0 - np.exp(-t)), tilt_speed / 10.0 * (1.0 - np.exp(-10.0 * t))
    a = np.asarray(yaw_axis, float) / np.linalg.norm(yaw_axis)
    b = np.asarray(tilt_axis, float) - (np.dot(tilt_axis, a)) * a
    orientation = quaternion.multiply(quaternion.from_rotation_vector(yaw[:, None] * a),
                                      quaternion.from_rotation_vector(tilt[:, None] * b / np.linalg.norm(b)))  # fmt: skip
    return Trace.from_samples(name, t, np.zeros((len(t), 3)), orientation)


def test_a_yaw_and_a_tilt_dying_away_at_different_rates_are_weighed_apart():
    traces, groups = people([yaw_and_tilt("a", (0, 1, 0), (1, 0, 0), 2.0, 1.0), yaw_and_tilt("b", (0.3, 1, 0), (0, 0, 1), 1.5, 0.8),
                             yaw_and_tilt("c", (0, 0.2, 1), (1, 0, 0), 2.5, 1.2)])  # fmt: skip
    for fold in headroom(traces, groups, HORIZONS_MS):
        for h in HORIZONS_MS:
            assert fold.ratios["yaw/tilt"][h] < 0.75 * fold.ratios["shared"][h], (fold.group, h)
        # The three people turn about three different axes in the world frame.
        assert fold.ratios["per axis"][100.0] > 1.0


def test_a_person_recorded_twice_the_same_weighs_as_once():
    heads = noisy_heads()
    traces, groups = people(heads)
    twice = dict(traces, again=replace(heads[0], name="again"))
    once = headroom(traces, groups, HORIZONS_MS)
    doubled = headroom(twice, dict(groups, p0=["p0", "again"]), HORIZONS_MS)
    for a, b in zip(once, doubled):
        for fit in FITS:
            assert b.ratios[fit] == pytest.approx(a.ratios[fit], rel=1e-9)


def test_a_held_out_group_is_not_in_its_own_fit():
    """The held-out person's score is the fit made on the others applied to each of their recordings:
    with a second, different recording added to that person, their score is the geometric mean of
    the two scored alone, which holds only if neither was fitted on."""
    heads = noisy_heads(4)
    traces, groups = people(heads)
    other = head_motion(4.0, 90.0, seed=99, name="other").with_noise(0.0, math.radians(0.5), seed=99)
    alone = headroom(traces, groups, HORIZONS_MS)[0]
    other_alone = headroom(dict(traces, p0=replace(other, name="p0")), groups, HORIZONS_MS)[0]
    both = headroom(dict(traces, other=other), dict(groups, p0=["p0", "other"]), HORIZONS_MS)[0]
    for fit in FITS:
        for h in HORIZONS_MS:
            assert both.ratios[fit][h] ** 2 == pytest.approx(alone.ratios[fit][h] * other_alone.ratios[fit][h], rel=1e-9)
            assert other_alone.ratios[fit][h] != pytest.approx(alone.ratios[fit][h], rel=1e-3)


def test_fewer_than_two_groups_give_no_folds():
    traces, groups = people(noisy_heads(1))
    assert headroom(traces, groups, HORIZONS_MS) == []


def test_a_gap_restarts_the_averages_and_a_repeated_time_is_skipped():
    trace = decaying_turn("gap", (0, 0, 1), 2.0, rate_hz=50.0, seconds=1.0)
    t = trace.t.copy()
    t[25:] += 2.0  # a 2 s gap before sample 25: longer than max_gap
    orientation = np.insert(trace.orientation, 10, trace.orientation[10], axis=0)
    t = np.insert(t, 10, t[10] + 1e-8)  # a repeat 10 ns after sample 10
    anchors = anchors_of(Trace.from_samples("gap", t, np.zeros((len(t), 3)), orientation))
    # Samples 1-24 and 26-50 have velocities: the first sample and the first after the gap do not.
    assert len(anchors.t) == 24 + 25
    before, restart = anchors.features[23], anchors.features[24]
    assert np.linalg.norm(before[1]) > 1e-3  # the rate was dying away: the newest velocity is below its averages
    assert np.allclose(restart[1:], 0.0) and np.linalg.norm(restart[0]) > 0.3


def test_sign_flips_read_as_the_small_turns_they_are():
    trace = noisy_heads(1)[0]
    flipped = trace.orientation * np.where(np.arange(len(trace)) % 2, -1.0, 1.0)[:, None]
    plain = anchors_of(trace)
    mixed = anchors_of(Trace.from_samples(trace.name, trace.t, trace.position, flipped))
    np.testing.assert_allclose(mixed.features, plain.features, atol=1e-9)


@settings(max_examples=20, deadline=None)
@given(st.floats(0.2, 4.0), st.floats(30.0, 240.0))
def test_constant_velocity_s_features_are_its_velocity_alone(speed, rate_hz):
    """At a steady rate every average equals the velocity: the differences vanish, whatever the rate."""
    t = np.arange(int(rate_hz) + 1) / rate_hz
    orientation = quaternion.from_rotation_vector(speed * t[:, None] * np.array([0.6, 0.0, 0.8]))
    anchors = anchors_of(Trace.from_samples("steady", t, np.zeros((len(t), 3)), orientation))
    np.testing.assert_allclose(anchors.features[:, 0], np.broadcast_to(speed * np.array([0.6, 0.0, 0.8]), (len(t) - 1, 3)), rtol=1e-9, atol=1e-12 * speed)
    np.testing.assert_allclose(anchors.features[:, 1:], 0.0, atol=1e-9 * speed)


def test_others_at_rest_leave_a_fold_unscored():
    """Nothing to fit where every other person holds still: the held-out ratios are NaN, not an error."""
    still = [Trace.from_samples(f"s{k}", np.arange(200) / 60.0, np.zeros((200, 3)), np.tile([1.0, 0.0, 0.0, 0.0], (200, 1)))
             for k in range(2)]  # fmt: skip
    traces, groups = people([decaying_turn("moving", (0, 1, 0), 2.0), *still])
    folds = headroom(traces, groups, HORIZONS_MS)
    assert all(math.isnan(v) for fit in FITS for v in folds[0].ratios[fit].values())
    assert all(math.isnan(v) for fit in FITS for v in folds[1].ratios[fit].values())  # still: no error to compare


def test_the_features_are_those_rls_learns_from():
    """Fed the same samples, `rls` holds the same features at every sample with a velocity."""
    trace = noisy_heads(1)[0]
    t = trace.t.copy()
    t[100:] += 1.5  # and a gap that restarts both
    trace = Trace.from_samples(trace.name, t, trace.position, trace.orientation)
    rls = make("rls")
    held = []
    for sample in trace.samples():
        rls.update(sample)
        features = rls._anchors[-1][2]
        if features is not None:
            held.append(np.reshape(features, (4, 3)))
    np.testing.assert_allclose(anchors_of(trace).features, np.array(held), rtol=1e-9, atol=1e-12)
