"""The refresh model fitted to swap times: period and phase found through jitter and missed
refreshes, kept up with a drifting display clock, and an unpaced display refused."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rig.devices.window.refresh import REFIT_EVERY, RefreshModel
from rig.errors import RigError

PERIOD = 1.0 / 60.0


def _swaps(count: int, period: float = PERIOD, t0: float = 3.0, jitter: float = 2e-4, skip: tuple[int, ...] = (), seed: int = 0) -> np.ndarray:
    k = np.array([i for i in range(count) if i not in skip], dtype=float)
    return t0 + k * period + np.random.default_rng(seed).uniform(0.0, jitter, k.size)


def test_the_period_and_the_blank_are_found_through_jitter_and_missed_refreshes() -> None:
    times = _swaps(90, skip=(10, 11, 40))
    model = RefreshModel.fit(times)
    assert model.period_s == pytest.approx(PERIOD, rel=1e-4)
    # the phase follows the swaps' lower edge: the blank, not the swaps' mean lag
    assert abs(model.vblank(0) - 3.0) < 1e-4
    assert model.slot(times[-1]) == 89


def test_a_display_that_does_not_pace_swaps_is_refused() -> None:
    with pytest.raises(RigError, match="vsync is off"):
        RefreshModel.fit(np.arange(50) * 3e-4)


def test_scattered_swaps_are_refused() -> None:
    times = np.cumsum(np.random.default_rng(1).uniform(0.005, 0.03, 60))
    with pytest.raises(RigError, match="not regular"):
        RefreshModel.fit(times)


def test_the_model_follows_a_display_clock_that_drifts() -> None:
    model = RefreshModel.fit(_swaps(60))
    drifted = PERIOD * (1.0 + 200e-6)
    for k in range(60, 60 + 20 * REFIT_EVERY):
        model.observe(k, 3.0 + 60 * PERIOD + (k - 60) * drifted)
    assert model.period_s == pytest.approx(drifted, rel=2e-5)


@given(st.floats(-100.0, 100.0), st.floats(1.0 / 240.0, 1.0 / 24.0))
def test_a_time_at_a_blank_is_before_the_refresh_after_it(t: float, period: float) -> None:
    model = RefreshModel(0.25, period)
    k = model.refresh_after(t)
    assert model.vblank(k - 1) <= t + 1e-9 < model.vblank(k) + 1e-9
