"""The on-fraction of a row's exposure, its derivatives, and the readings a film cannot tell apart."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from analysis.shutter.model import on_fraction, on_fraction_derivatives, other_readings

exposures = st.floats(0.005, 2.5)
duties = st.floats(0.02, 0.98)


def sampled_on_fraction(u: float, exposure: float, duty: float, samples: int = 200_000) -> float:
    """The share of [u, u + exposure] the light is on, by counting sample points."""
    points = u + (np.arange(samples) + 0.5) / samples * exposure
    return float(np.mean((points - np.floor(points)) < duty))


@given(st.floats(-50.0, 50.0), exposures, duties)
def test_on_fraction_is_the_share_of_the_window_the_light_is_on(u, exposure, duty):
    assert abs(on_fraction(np.array(u), exposure, duty) - sampled_on_fraction(u, exposure, duty)) < 1e-4


@given(exposures, duties)
def test_on_fraction_averages_to_the_duty_over_a_period(exposure, duty):
    u = (np.arange(4000) + 0.5) / 4000
    assert abs(on_fraction(u, exposure, duty).mean() - duty) < 1e-3


@given(st.floats(-5.0, 5.0), st.floats(0.01, 0.9), st.floats(0.05, 0.95))
def test_derivatives_match_finite_differences_away_from_kinks(u, exposure, duty):
    step = 1e-7
    points = np.array([u, u + exposure])
    edges = np.concatenate([np.floor(points), np.floor(points) + duty, np.floor(points) + 1.0])
    if np.min(np.abs(points[:, None] - edges[None, :])) < 1e-5 or min(duty, 1 - duty) < 1e-5:
        return
    value = on_fraction(np.array(u), exposure, duty)
    by_u, by_exposure, by_duty = on_fraction_derivatives(np.array(u), exposure, duty, value)
    assert np.isclose(by_u, (on_fraction(np.array(u + step), exposure, duty) - value) / step, atol=1e-4 / exposure)
    assert np.isclose(by_exposure, (on_fraction(np.array(u), exposure + step, duty) - value) / step, atol=1e-4 / exposure)
    assert np.isclose(by_duty, (on_fraction(np.array(u), exposure, duty + step) - value) / step, atol=1e-4 / exposure)


@given(st.floats(0.02, 0.98), st.floats(0.01, 0.99))
def test_every_other_reading_gives_the_same_normalised_rows(duty, share):
    exposure = share * min(duty, 1.0 - duty)
    u = (np.arange(20_000) + 0.5) / 20_000

    def normalised(e: float, d: float) -> np.ndarray:
        g = on_fraction(u, e, d)
        return np.sort((g - g.min()) / (g.max() - g.min()))

    for reading in other_readings(exposure, duty):
        assert np.allclose(normalised(reading.exposure, reading.duty), normalised(exposure, duty), atol=2e-3)
