"""Films that cannot decide the readout or the exposure are refused in one line that says what to
change; so are inputs out of range."""

import numpy as np
import pytest

from analysis import AnalysisError
from analysis.shutter import ShutterOptions, estimate_shutter, film_of_frames


def refusal(film, duty=0.25, frames=None, flash_hz=None, **options):
    made, times = film.frames()
    made = made if frames is None else frames
    with pytest.raises(AnalysisError) as error:
        estimate_shutter(film_of_frames(made, times), flash_hz or film.flash_hz, ShutterOptions(duty=duty, **options))
    message = str(error.value)
    assert "\n" not in message
    return message


def test_an_exposure_longer_than_the_light_is_on_is_refused(flash_film):
    message = refusal(flash_film(flash_hz=310, exposure_s=1e-3))  # on for 0.81 ms of each 3.2 ms
    assert "ramps meet" in message and "flash at most" in message


def test_an_exposure_filling_the_light_s_on_time_is_refused(flash_film):
    message = refusal(flash_film(fps=30, readout_s=25e-3, exposure_s=4e-3, flash_hz=61.3, duration_s=3))
    assert "ramps meet" in message


def test_an_exposure_over_half_the_period_of_a_square_wave_is_refused(flash_film):
    # 0.7 of a period reads like 0.3 of one; only the frame interval could tell them apart, and it allows both.
    film = flash_film(fps=60, readout_s=14e-3, exposure_s=0.7 / 130.3, flash_hz=130.3, duty=0.5, duration_s=1)
    message = refusal(film, duty=0.5)
    assert "cannot tell an exposure of 2.30 ms from one of 5.37 ms" in message
    assert "--duty" in message and "flash at most" in message


def test_a_square_wave_too_fast_for_the_frame_interval_is_refused_until_the_longest_exposure_is_given(flash_film):
    film = flash_film(fps=240, readout_s=3.5e-3, exposure_s=0.5e-3, flash_hz=505, duty=0.5, duration_s=1)
    assert "cannot tell an exposure" in refusal(film, duty=0.5)
    frames, times = film.frames()
    result = estimate_shutter(film_of_frames(frames, times), 505, ShutterOptions(duty=0.5, max_exposure_s=1e-3))
    assert result.exposure_s == pytest.approx(0.5e-3, rel=0.02)


def test_an_unknown_duty_cycle_leaves_exposure_and_duty_undecided(flash_film):
    assert "cannot tell an exposure" in refusal(flash_film(readout_s=7e-3, flash_hz=81.3), duty=None)


def test_a_wrong_duty_cycle_is_refused(flash_film):
    message = refusal(flash_film(readout_s=7e-3, flash_hz=81.3, duty=0.4), duty=0.25)
    assert "on 40% of each period, not the 25% given" in message


def test_too_few_frames_are_refused(flash_film):
    assert "only 30 frames" in refusal(flash_film(readout_s=7e-3, flash_hz=81.3, duration_s=0.25))


def test_saturation_everywhere_is_refused(flash_film):
    assert "saturates all" in refusal(flash_film(readout_s=7e-3, flash_hz=81.3, on_dn=600))


def test_a_film_without_a_flashing_light_is_refused(flash_film):
    film = flash_film(readout_s=7e-3, flash_hz=81.3)
    still = np.full((180, 160, 24), 40, dtype=np.uint8)
    assert "no flashing light found" in refusal(film, frames=still)


def test_a_flash_at_a_multiple_of_the_frame_rate_looks_still_and_is_refused(flash_film):
    message = refusal(flash_film(readout_s=7e-3, exposure_s=0.3e-3, flash_hz=120.0))
    assert "no flashing light found" in message and "no multiple of the frame rate" in message


def test_bands_that_only_alternate_are_refused(flash_film):
    message = refusal(flash_film(readout_s=7e-3, exposure_s=0.3e-3, flash_hz=180.0))
    assert "too few phases" in message and "such as 165.8 Hz" in message


def test_a_flash_drifting_slowly_against_half_the_frame_rate_is_refused(flash_film, panel):
    # 14.925 Hz at 30 fps: odd frames see the complement of even ones, and the pattern only drifts by
    # 0.9 of a period over 6 s; flash frequencies 0.06 % apart fit as well, with readouts 27 to 33 ms.
    film = flash_film(fps=30, readout_s=31.67e-3, exposure_s=4.17e-3, flash_hz=59.7 / 4, duty=0.5, duration_s=6, height=240,
                      width=16, panel=panel(59.7, 29, 182))  # fmt: skip
    message = refusal(film, duty=0.5, source="display", display_hz=59.7, scanout_share=1.0)
    assert "only known to be" in message and "film longer" in message


def test_a_wrong_flash_frequency_is_refused(flash_film):
    message = refusal(flash_film(readout_s=7e-3, flash_hz=81.3), flash_hz=95.0)
    assert "do not follow a light flashing at 95 Hz" in message


def test_a_display_without_its_scan_out_share_cannot_decide_a_short_readout(flash_film, panel):
    film = flash_film(fps=240, readout_s=3.5e-3, exposure_s=4e-3, flash_hz=30.0, duty=0.5, height=200, duration_s=2,
                      panel=panel(60.0, 30, 150))  # fmt: skip
    message = refusal(film, duty=0.5, source="display", display_hz=60.0)
    assert "display's scan-out" in message


def test_a_display_reaching_the_frame_s_edge_is_refused(flash_film, panel):
    film = flash_film(fps=120, readout_s=7e-3, exposure_s=2e-3, flash_hz=30.0, duty=0.5, duration_s=2, panel=panel(60.0, 0, 160))
    assert "panel's whole height" in refusal(film, duty=0.5, source="display", display_hz=60.0, scanout_share=1.0)


def test_a_flash_frequency_that_is_not_one_is_refused(flash_film):
    assert "flash frequency must be a positive number of Hz" in refusal(flash_film(readout_s=7e-3, flash_hz=81.3), flash_hz=-5.0)


@pytest.mark.parametrize(
    "options, words",
    [
        ({"duty": 1.2}, "duty must be a positive number below 1"),
        ({"max_exposure_s": 0.0}, "max_exposure_s must be a positive number of seconds"),
        ({"scanout": "left-right"}, "scanout must be one of top-down, bottom-up"),
        ({"source": "display"}, "give its refresh rate (--display-hz)"),
        ({"display_hz": 60.0}, "give --source display with it"),
    ],
)
def test_options_out_of_range_are_refused(options, words):
    with pytest.raises(AnalysisError) as error:
        ShutterOptions(**options)
    assert words in str(error.value)
