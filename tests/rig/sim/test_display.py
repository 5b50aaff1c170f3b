"""Display timing: vertical blanks, scan-out row by row, sample-and-hold."""

import numpy as np
import pytest

from rig.errors import ConfigError
from rig.sim.display import DisplayConfig, SimDisplay
from rig.sim.display_config import COMMON_REFRESH_HZ


@pytest.fixture(params=COMMON_REFRESH_HZ, ids=lambda hz: f"{hz:g}Hz")
def display(request: pytest.FixtureRequest) -> SimDisplay:
    return SimDisplay(DisplayConfig(refresh_hz=request.param, t0=0.25))


def test_vblanks_are_one_period_apart(display: SimDisplay) -> None:
    times = display.vblank_time(np.arange(10))
    assert times[0] == 0.25
    np.testing.assert_allclose(np.diff(times), 1.0 / display.config.refresh_hz, rtol=1e-12)


def test_frame_finished_between_blanks_appears_at_the_next_blank(display: SimDisplay) -> None:
    t = display.vblank_time(3) + 0.3 * display.period_s
    assert display.refresh_after(t) == 4


def test_frame_finished_exactly_at_a_blank_misses_it(display: SimDisplay) -> None:
    assert display.refresh_after(display.vblank_time(5)) == 6


def test_scanout_runs_top_to_bottom_over_one_period(display: SimDisplay) -> None:
    assert display.scanout_delay(0.0) == 0.0
    assert display.scanout_delay(1.0) == pytest.approx(display.period_s)
    assert display.scanout_delay(0.25) == pytest.approx(0.25 * display.period_s)
    assert display.photon_time(2, 0.5) == pytest.approx(display.vblank_time(2) + 0.5 * display.period_s)


def test_each_row_holds_its_refresh_until_scanned_again(display: SimDisplay) -> None:
    period = display.period_s
    v = display.vblank_time(7)
    # Just after the blank only the top row shows refresh 7; the middle still shows refresh 6.
    assert display.refresh_shown(np.array(v + 1e-9), np.array(0.0)) == 7
    assert display.refresh_shown(np.array(v + 1e-9), np.array(0.5)) == 6
    assert display.refresh_shown(np.array(v + 0.5 * period + 1e-9), np.array(0.5)) == 7
    # Sample-and-hold: the middle row keeps refresh 7 until refresh 8 reaches it.
    assert display.refresh_shown(np.array(v + 1.5 * period - 1e-9), np.array(0.5)) == 7
    assert display.refresh_shown(np.array(v + 1.5 * period + 1e-9), np.array(0.5)) == 8


def test_rows_before_the_first_refresh_show_nothing(display: SimDisplay) -> None:
    assert display.refresh_shown(np.array(0.0), np.array(0.0)) == -1


def test_partial_scanout_fraction_leaves_a_blanking_interval() -> None:
    display = SimDisplay(DisplayConfig(refresh_hz=60.0, scanout_fraction=0.9))
    assert display.scanout_delay(1.0) == pytest.approx(0.9 / 60.0)


@pytest.mark.parametrize("bad", [dict(refresh_hz=0.0), dict(refresh_hz=-60.0), dict(refresh_hz=float("nan")), dict(width=4), dict(scanout_fraction=0.0)])
def test_bad_display_settings_are_rejected(bad: dict) -> None:
    with pytest.raises(ConfigError):
        DisplayConfig(**bad)
