"""Scores by group and choices made without the group scored: ratios to constant velocity, geometric
means over groups, choosing, and folds that never see the group they score."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import Trace
from predictors.corpus import Recording
from predictors.cross_validation import CorpusScores, cross_validate, geometric_mean, groups_of, held_out_mean
from predictors.evaluation import Evaluation, HorizonScore

HORIZONS = (20.0, 50.0)


def evaluation(name: str, recording: str, angular: float, position: float = 0.0) -> Evaluation:
    scores = tuple(HorizonScore(h, 100, position, 2.0 * position, 3.0 * position, angular, 2.0 * angular, 3.0 * angular, 0.0, 0.0)
                   for h in HORIZONS)  # fmt: skip
    return Evaluation(name, {}, recording, 100, 1.0, scores)


def corpus(errors: dict[str, dict[str, float]], positions: dict[str, dict[str, float]] | None = None) -> CorpusScores:
    """Scores from each candidate's angular RMS error on each recording (the same at every horizon)."""
    positions = positions or {}
    return CorpusScores({c: {r: evaluation(c, r, e, positions.get(c, {}).get(r, 0.0)) for r, e in by.items()} for c, by in errors.items()},
                        "slerp", HORIZONS)  # fmt: skip


def test_a_ratio_is_the_error_over_constant_velocitys_and_position_is_nan_without_position():
    scores = corpus({"slerp": {"a": 2.0}, "x": {"a": 1.5}})
    assert scores.ratio("x", "a", "angular", 50.0) == 0.75
    assert scores.ratio("x", "a", "angular_p95", 50.0) == 0.75
    assert math.isnan(scores.ratio("x", "a", "position", 50.0))


def test_a_person_recorded_twice_counts_once_in_the_geometric_mean_over_groups():
    scores = corpus({"slerp": {"a1": 1.0, "a2": 1.0, "b": 1.0}, "x": {"a1": 0.5, "a2": 0.5, "b": 2.0}})
    groups = {"A": ["a1", "a2"], "B": ["b"]}
    assert scores.corpus_ratio("x", groups, "angular", 20.0) == pytest.approx(1.0)
    assert geometric_mean([0.5, 0.5, 2.0]) == pytest.approx(0.5 ** (1 / 3))


def test_choosing_refuses_a_candidate_worse_than_constant_velocity_on_any_recording():
    scores = corpus({"slerp": {"a": 1.0, "b": 1.0}, "bold": {"a": 0.3, "b": 1.01}, "safe": {"a": 0.9, "b": 0.95}})
    assert scores.choose({"A": ["a"], "B": ["b"]}) == "safe"
    assert scores.choose({"A": ["a"]}) == "bold"


def test_choosing_weighs_position_where_recordings_have_it():
    errors = {"slerp": {"a": 1.0}, "turns": {"a": 0.8}, "moves": {"a": 0.9}}
    positions = {"slerp": {"a": 1.0}, "turns": {"a": 1.0}, "moves": {"a": 0.5}}
    assert corpus(errors, positions).choose({"A": ["a"]}) == "moves"
    assert corpus(errors).choose({"A": ["a"]}) == "turns"


def test_each_fold_chooses_without_the_group_it_scores():
    # "local" is best on person A alone, "broad" on the others: only A's fold keeps "broad".
    errors = {"slerp": {"a": 1.0, "b": 1.0, "c": 1.0}, "local": {"a": 0.2, "b": 0.95, "c": 0.95},
              "broad": {"a": 0.9, "b": 0.7, "c": 0.7}}  # fmt: skip
    folds = cross_validate(corpus(errors), {"A": ["a"], "B": ["b"], "C": ["c"]})
    assert [(f.group, f.chosen) for f in folds] == [("A", "broad"), ("B", "local"), ("C", "local")]
    assert [f.ratios["angular"][50.0] for f in folds] == pytest.approx([0.9, 0.95, 0.95])
    assert held_out_mean(folds, "angular", 50.0) == pytest.approx((0.9 * 0.95 * 0.95) ** (1 / 3))


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(0.2, 2.0), min_size=3, max_size=3), st.lists(st.floats(0.2, 2.0), min_size=3, max_size=3))
def test_a_fold_scores_a_candidate_chosen_on_the_other_groups_alone(first, second):
    errors = {"slerp": {"a": 1.0, "b": 1.0, "c": 1.0}, "p": dict(zip("abc", first)), "q": dict(zip("abc", second))}
    groups = {"A": ["a"], "B": ["b"], "C": ["c"]}
    scores = corpus(errors)
    for fold in cross_validate(scores, groups):
        others = {g: m for g, m in groups.items() if g != fold.group}
        assert fold.chosen == scores.choose(others)
        held = dict(errors[fold.chosen])
        assert fold.ratios["angular"][20.0] == pytest.approx(held[fold.recordings[0]])


def test_groups_leave_out_recordings_apart_and_without_the_label():
    trace = Trace.from_samples("r", np.arange(3.0), np.zeros((3, 3)), np.tile([1.0, 0, 0, 0], (3, 1)))
    recordings = [Recording(trace, "hmd", "hmd/u1", "nyc", False),
                  Recording(Trace.from_samples("robot", trace.t, trace.position, trace.orientation), "quest", "robot", None, True),
                  Recording(Trace.from_samples("s", trace.t, trace.position, trace.orientation), "quest", "quest/u2", None, False)]  # fmt: skip
    assert groups_of(recordings, "person") == {"hmd/u1": ["r"], "quest/u2": ["s"]}
    assert groups_of(recordings, "scene") == {"nyc": ["r"]}
    assert groups_of(recordings, "device") == {"hmd": ["r"], "quest": ["s"]}
