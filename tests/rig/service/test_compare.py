"""Comparing groups: pooled by their intervals, a difference called only where the intervals allow."""

from __future__ import annotations

import numpy as np
import pytest

from rig.service.compare import Z95, differences, group_latencies


def rows(system: str, values: list[float], half_width: float) -> list[dict]:
    return [{"system": system, "latency_ms": v, "ci95_low_ms": v - half_width, "ci95_high_ms": v + half_width} for v in values]


def test_agreeing_videos_pool_to_a_narrower_interval() -> None:
    (group,) = group_latencies(rows("a", [40.0, 40.0, 40.0, 40.0], 1.0), "system")
    assert group.latency_ms == pytest.approx(40.0)
    assert group.se_ms == pytest.approx(1.0 / Z95 / 2.0)


def test_videos_that_disagree_beyond_their_intervals_are_not_believed() -> None:
    (group,) = group_latencies(rows("a", [30.0, 50.0], 0.5), "system")
    assert group.se_ms == pytest.approx(np.std([30.0, 50.0], ddof=1) / np.sqrt(2))


def test_a_difference_is_called_only_when_its_interval_excludes_zero() -> None:
    data = rows("hold", [42.0, 42.2], 0.3) + rows("slerp", [30.0, 30.1], 0.3) + rows("slerp-again", [30.05], 0.3)
    verdicts = {(d.a, d.b): d for d in differences(group_latencies(data, "system"))}
    assert verdicts["hold", "slerp"].differs and verdicts["hold", "slerp"].difference_ms == pytest.approx(-12.05, abs=0.01)
    assert not verdicts["slerp", "slerp-again"].differs


def test_rows_without_an_interval_are_left_out() -> None:
    data = rows("a", [10.0], 1.0) + [{"system": "a", "latency_ms": None, "ci95_low_ms": None, "ci95_high_ms": None}]
    assert group_latencies(data, "system")[0].videos == 1


def test_only_rows_under_the_same_conditions_are_pooled_and_compared() -> None:
    def at(period_s: float, system: str, value: float) -> dict:
        return {"system": system, "period_s": period_s, "latency_ms": value, "ci95_low_ms": value - 0.3, "ci95_high_ms": value + 0.3}

    data = [at(1.0, "a", 1.0), at(1.0, "a", 1.1), at(2.0, "a", 3.0), at(1.0, "b", 5.0), at(2.0, "b", 7.0)]
    groups = group_latencies(data, "system", ["period_s"])
    assert [(g.name, g.conditions, g.videos) for g in groups] == [
        ("a", (("period_s", "1.0"),), 2), ("a", (("period_s", "2.0"),), 1), ("b", (("period_s", "1.0"),), 1), ("b", (("period_s", "2.0"),), 1),
    ]
    assert groups[0].latency_ms == pytest.approx(1.05)
    compared = [(d.a, d.b, d.difference_ms) for d in differences(groups)]
    assert compared == [("a", "b", pytest.approx(3.95)), ("a", "b", pytest.approx(4.0))]


def test_a_group_carries_its_truth_and_error_where_every_row_knows_it() -> None:
    known = [dict(row, truth_ms=39.0) for row in rows("a", [40.0, 40.0], 1.0)]
    (group,) = group_latencies(known, "system")
    assert (group.truth_ms, group.error_ms) == (39.0, pytest.approx(1.0))
    (unknown,) = group_latencies(known[:1] + rows("a", [40.0], 1.0), "system")
    assert unknown.truth_ms is None and unknown.error_ms is None
