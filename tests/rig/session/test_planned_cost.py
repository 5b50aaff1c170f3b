"""The cost a compositing server plans its next composition for, from the costs it measured."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rig.session.timing import latency_minimising_cost

REFRESH_S = 1 / 60


def expected_delay(plan_s: float, costs_s: list[float], miss_s: float) -> float:
    return plan_s + miss_s * np.mean(np.asarray(costs_s) > plan_s)


def test_a_steady_cost_is_planned_for_in_full() -> None:
    costs = [0.005 + 0.0001 * (k % 7) for k in range(60)]
    assert latency_minimising_cost(costs, 3 * REFRESH_S) == max(costs)


def test_a_lone_stall_is_not_planned_for() -> None:
    costs = [0.006] * 59 + [0.120]
    assert latency_minimising_cost(costs, 3 * REFRESH_S) == 0.006


def test_a_heavy_tail_is_cut_where_waiting_longer_costs_more_than_the_misses_it_saves() -> None:
    """Half the costs 5 ms, half 40 ms, a miss worth 20 ms: planning for 40 ms adds 35 ms to every
    image to save 10 ms of misses on average."""
    costs = [0.005, 0.040] * 30
    assert latency_minimising_cost(costs, 0.020) == 0.005
    assert latency_minimising_cost(costs, 0.100) == 0.040


@given(st.lists(st.floats(1e-4, 0.2), min_size=1, max_size=80), st.floats(0.0, 0.2))
def test_the_plan_is_a_measured_cost_with_the_least_expected_delay(costs, miss_s) -> None:
    plan = latency_minimising_cost(costs, miss_s)
    assert plan in costs
    assert expected_delay(plan, costs, miss_s) == pytest.approx(min(expected_delay(c, costs, miss_s) for c in costs), abs=1e-12)
