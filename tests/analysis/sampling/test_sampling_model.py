"""The camera-display sampling bias, g(s, e), against its closed forms and the laws it obeys."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.sampling.model import bias_range_s, commensurate, exposure_bias, frame_phases

PHASES = np.linspace(0.0, 1.0, 4000, endpoint=False)


@given(st.floats(0.01, 3.0))
def test_the_bias_averages_to_zero_over_the_phases(e: float) -> None:
    assert exposure_bias(PHASES, e).mean() == pytest.approx(0.0, abs=1e-6)


@given(st.integers(1, 4), st.floats(0.0, 0.999))
def test_an_exposure_of_whole_refreshes_has_no_bias(refreshes: int, s: float) -> None:
    assert exposure_bias(s, float(refreshes)) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("e", [0.05, 0.25, 0.5, 0.9])
def test_a_short_exposure_is_off_by_the_mean_age_of_the_refresh_it_sees(e: float) -> None:
    # No switch in [s, s + e]: the frame sees content s + e / 2 old on average, against T / 2.
    s = np.linspace(0.0, 1.0 - e, 50)
    np.testing.assert_allclose(exposure_bias(s, e), s + e / 2 - 0.5, atol=1e-12)
    assert np.abs(exposure_bias(PHASES, e)).max() == pytest.approx((1 - e) / 2, abs=1e-3)


@pytest.mark.parametrize(
    ("camera_fps", "display_hz", "exposure_s", "bound_s"),
    [
        (240.0, 60.0, 1 / 480, (1 / 240 - 1 / 480) / 2),  # four phases, half-frame exposure: 1.04 ms
        (60.0, 60.0, 1 / 240, (1 / 60 - 1 / 240) / 2),  # phase-locked, quarter-refresh exposure: 6.25 ms
        (60.0, 60.0, 1 / 60, 0.0),  # a whole refresh
        (240.0, 60.0, 1 / 240, 0.0),  # four exposures tile the refresh
        (239.0, 60.0, 1 / 480, 0.0),  # incommensurate: the phases walk through the refresh
    ],
)
def test_bias_bound_for_commensurate_rates(camera_fps: float, display_hz: float, exposure_s: float, bound_s: float) -> None:
    assert bias_range_s(display_hz, camera_fps, exposure_s) == pytest.approx(bound_s, abs=1e-9)


def test_the_bias_bound_matches_the_phases_a_camera_visits() -> None:
    # 90 fps on 60 Hz visits three phases; the mean of their biases spans the bound.
    frames = np.arange(3) / 90.0
    offsets = np.linspace(0.0, 1.0, 2000, endpoint=False)
    means = exposure_bias(frame_phases(frames, 60.0, offsets), 0.05 * 60 / 90).mean(axis=0) / 60.0
    assert np.ptp(means) / 2 == pytest.approx(bias_range_s(60.0, 90.0, 0.05 / 90), rel=1e-3)


def test_commensurate_rates() -> None:
    assert commensurate(240 / 60) == (4, 1)
    assert commensurate(90 / 60) == (3, 2)
    assert commensurate(60 / 120) == (1, 2)
    assert commensurate(59.94 / 60) == (999, 1000)
    assert commensurate(239.0 / 60.0 * (1 + 1e-7)) is None
