"""The sphere's rows switch one after another: its bias is g averaged over its rows' phases, which the
smeared tables give, and the slope grid holds every slope a display and a camera allow."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.sampling.model import exposure_bias
from analysis.sampling.folding import bias_table
from analysis.sampling.rows import COARSE_STEP_REFRESHES, SphereRows, disc_kernel

BINS = 512
CENTRES = (np.arange(BINS) + 0.5) / BINS


def by_rows(function, s: np.ndarray, e: float, radius: float, rows: int = 4001) -> np.ndarray:
    """``function`` averaged over a disc's rows spread over +-``radius`` refreshes, row by row."""
    u = np.linspace(-radius, radius, rows)
    chord = np.sqrt(np.maximum(radius**2 - u**2, 0.0))
    return (function((s[:, None] - u[None, :]) % 1.0, e) * chord).sum(axis=1) / chord.sum()


@given(st.floats(0.0, 0.6))
def test_the_kernel_is_a_disc_of_the_rows_variance(radius: float) -> None:
    kernel = disc_kernel(radius, BINS)
    assert kernel.sum() == pytest.approx(1.0)
    offsets = (np.arange(BINS) + BINS // 2) % BINS - BINS // 2
    assert np.allclose(kernel, kernel[(-np.arange(BINS)) % BINS])
    if radius < 0.5:
        # A disc's rows have variance radius^2 / 4, to within the bins' own width.
        assert kernel @ (offsets / BINS) ** 2 == pytest.approx(radius**2 / 4 + 1 / (12 * BINS**2), abs=2e-6)


@pytest.mark.parametrize(("e", "radius"), [(0.125, 0.07), (0.3, 0.02), (0.5, 0.2), (0.05, 0.4)])
def test_smeared_tables_are_the_bias_averaged_row_by_row(e: float, radius: float) -> None:
    g = bias_table(1.0, np.array([e]), BINS, np.fft.rfft(disc_kernel(radius, BINS)))[0]
    np.testing.assert_allclose(g, by_rows(exposure_bias, CENTRES, e, radius), atol=2e-3)
    assert g.mean() == pytest.approx(exposure_bias(CENTRES, e).mean(), abs=1e-9)
    assert np.ptp(g) <= np.ptp(exposure_bias(CENTRES, e)) + 1e-9


def test_the_slopes_reach_from_the_readout_to_a_display_as_short_as_the_spheres_travel() -> None:
    # A 60 Hz display; a camera reading a row in 10 us to 30 us; a sphere 14 rows tall moving 8 rows.
    offsets = 4.0 * np.sin(np.linspace(0, 20, 500))
    rows = SphereRows(offsets, 3.5, 0.0, (10e-6, 30e-6))
    slopes = rows.slopes(60.0)
    assert slopes[0] == pytest.approx(-30e-6)
    assert slopes[-1] == pytest.approx(1 / (60.0 * rows.extent_px) - 10e-6)
    assert rows.extent_px == pytest.approx(np.ptp(offsets) + 14.0)
    # A step moves the disc's radius (7 rows) by at most the coarse step's share of a refresh.
    assert 60.0 * np.diff(slopes).max() * 7.0 <= COARSE_STEP_REFRESHES + 1e-12
    np.testing.assert_allclose(rows.shifts(1e-4), (1e-4 + 0.0) * offsets)


def test_a_point_on_one_row_has_one_slope() -> None:
    assert SphereRows(np.zeros(100), 0.0, 0.0, (0.0, 0.0)).slopes(60.0).tolist() == [0.0]


def test_fine_slopes_cover_the_coarse_ones_left_possible() -> None:
    rows = SphereRows(4.0 * np.sin(np.linspace(0, 20, 500)), 3.5, 0.0, (0.0, 0.0))
    coarse = rows.slopes(60.0)
    weights = np.exp(-0.5 * ((coarse - coarse[7]) / (coarse[1] - coarse[0])) ** 2)
    fine = rows.refined(60.0, coarse, weights)
    kept = coarse[weights >= 1e-6]
    assert fine[0] <= kept[0] and fine[-1] >= kept[-1]
    assert np.diff(fine).max() <= np.diff(coarse).max() / 4 + 1e-15
    assert math.isclose(fine[0], max(kept[0] - (coarse[1] - coarse[0]), coarse[0]))
