"""What a lab's film does to the shutter estimator, each hard case on its own: a light that covers
part of the frame, uneven light, noise, saturation, a duty cycle other than 50 %, a flash off its
stated frequency, frame times that vary or lie, a global shutter, a camera read bottom-up, and a
display whose own scan-out sweeps the rows."""

import numpy as np
import pytest

from analysis.shutter import ShutterOptions, estimate_shutter, film_of_frames, measure_shutter


def measure(film, duty=0.25, times=None, flash_hz=None, **options):
    frames, true_times = film.frames()
    read = ShutterOptions(duty=duty, **options)
    return estimate_shutter(film_of_frames(frames, true_times if times is None else times, read.roi), flash_hz or film.flash_hz, read)


def assert_covered(result, film, readout_tolerance=0.05, exposure_tolerance=0.10):
    assert result.readout_s == pytest.approx(film.readout_s, rel=readout_tolerance)
    assert result.exposure_s == pytest.approx(film.exposure_s, rel=exposure_tolerance)
    assert result.readout_ci95_s[0] <= film.readout_s <= result.readout_ci95_s[1]
    assert result.exposure_ci95_s[0] <= film.exposure_s <= result.exposure_ci95_s[1]


def test_a_light_covering_part_of_the_frame_is_found(flash_film):
    film = flash_film(width=64, height=240, light=(20, 50, 12, 100), readout_s=7e-3, flash_hz=81.3)
    result = measure(film)
    assert_covered(result, film)
    assert (result.rows[0], result.rows[1]) == (50, 149)


def test_a_region_around_the_light_gives_the_same_answer(flash_film):
    film = flash_film(width=64, height=240, light=(20, 50, 12, 100), readout_s=7e-3, flash_hz=81.3)
    result = measure(film, roi=(10, 30, 40, 150))
    assert_covered(result, film)
    assert result.frame_height == 240


def test_uneven_light_is_normalised_row_by_row(flash_film):
    film = flash_film(vignette=0.8, on_dn=200, readout_s=7e-3, flash_hz=81.3)
    assert_covered(measure(film), film)


def test_sensor_noise_over_a_narrow_light(flash_film):
    film = flash_film(fps=240, readout_s=3.5e-3, exposure_s=0.5e-3, flash_hz=183.1, light=(8, 0, 4, 160), noise_dn=6, duration_s=1)
    result = measure(film)
    assert_covered(result, film)
    assert result.misfit > 0.01  # the noise is seen, and does not stop the answer


def test_pixels_that_saturate_are_left_out(flash_film):
    film = flash_film(on_dn=300, vignette=0.6, readout_s=7e-3, flash_hz=81.3)
    result = measure(film)
    assert_covered(result, film)
    assert result.saturated_pixels > result.lit_pixels / 2
    assert any("saturate" in warning for warning in result.warnings)


def test_a_duty_cycle_other_than_half_is_fitted(flash_film):
    film = flash_film(duty=0.3, readout_s=7e-3, flash_hz=81.3)
    result = measure(film, duty=None, max_exposure_s=2e-3)
    assert_covered(result, film)
    assert result.duty == pytest.approx(0.3, abs=0.01)


def test_a_flash_off_its_stated_frequency_is_followed(flash_film):
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=2e-3, flash_hz=41.3 * 1.003, duration_s=3)
    result = measure(film, flash_hz=41.3)
    assert result.flash_hz_seen == pytest.approx(41.3 * 1.003, rel=1e-4)
    assert_covered(result, film)


def test_a_flash_not_commensurate_with_the_frame_rate_drifts_through_every_phase(flash_film):
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=2e-3, flash_hz=30.1, duration_s=6)
    assert_covered(measure(film), film)


def test_frame_times_that_vary_are_used_as_given(flash_film):
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=2e-3, flash_hz=41.3, jitter_s=2e-3, duration_s=2)
    result = measure(film)
    assert_covered(result, film)
    assert result.timing_rms_s < 20e-6
    assert result.warnings == ()


def test_frame_times_that_lie_are_noticed_and_the_exposure_interval_allows_for_them(flash_film):
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=2e-3, flash_hz=41.3, jitter_s=0.5e-3, duration_s=2)
    result = measure(film, times=np.arange(120) / 60)
    assert result.timing_rms_s > 0.2e-3
    assert any("frames' times" in warning for warning in result.warnings)
    assert_covered(result, film)


def test_a_global_shutter_reads_zero_with_a_bound(flash_film):
    film = flash_film(fps=240, readout_s=0.0, exposure_s=1e-3, flash_hz=101, duration_s=2)
    result = measure(film)
    assert result.global_shutter and result.readout_s == 0.0 and result.readout_direction is None
    assert result.readout_ci95_s[0] == 0.0 and 0.0 < result.readout_ci95_s[1] < 0.05e-3
    assert result.exposure_s == pytest.approx(1e-3, rel=0.02)
    assert result.ramp_rows is None


def test_a_camera_read_from_the_bottom(flash_film):
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=2e-3, flash_hz=41.3, bottom_up=True, duration_s=2)
    result = measure(film)
    assert_covered(result, film)
    assert result.readout_direction == "bottom-up"


@pytest.mark.parametrize("direction", ["top-down", "bottom-up"])
def test_a_display_flashing_full_field_has_its_scan_out_removed(flash_film, panel, direction):
    film = flash_film(fps=119.88, readout_s=7e-3, exposure_s=2e-3, flash_hz=30.0, duty=0.5, height=200, duration_s=2,
                      panel=panel(60.0, 30, 150, direction))  # fmt: skip
    result = measure(film, duty=0.5, source="display", display_hz=60.0, scanout=direction, scanout_share=1.0)
    assert_covered(result, film)
    assert result.source == "display" and result.readout_direction == "top-down"


def test_a_global_shutter_filming_a_display_sees_only_the_display_scan(flash_film, panel):
    film = flash_film(fps=240, readout_s=0.0, exposure_s=1e-3, flash_hz=30.0, duty=0.5, height=200, duration_s=2,
                      panel=panel(60.0, 30, 150))  # fmt: skip
    result = measure(film, duty=0.5, source="display", display_hz=60.0, scanout_share=1.0)
    assert result.global_shutter and result.readout_s == 0.0
    assert result.band_periods == pytest.approx(0.5 * 150 / 150, rel=0.05)


def test_a_video_file_is_read_with_its_frame_times(flash_film, mjpg_file, tmp_path):
    film = flash_film(fps=120, readout_s=7e-3, exposure_s=1e-3, flash_hz=81.3, width=32)
    frames, _ = film.frames()
    result = measure_shutter(mjpg_file(tmp_path / "flash.avi", frames, 120.0), 81.3, ShutterOptions(duty=0.25))
    assert_covered(result, film)
    assert result.frames == len(frames) and "container" in result.timing_source
