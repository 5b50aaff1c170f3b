"""Readout within 5 % and exposure within 10 %, each inside its 95 % interval, on films made from
the exact model at 30 to 240 fps, with the flash each film's camera is told to use."""

import pytest

from analysis.shutter import ShutterOptions, estimate_shutter, film_of_frames, suggest_flash_hz


def measure(film, duty):
    frames, times = film.frames()
    return estimate_shutter(film_of_frames(frames, times), film.flash_hz, ShutterOptions(duty=duty))


def assert_within(result, film):
    assert result.readout_s == pytest.approx(film.readout_s, rel=0.05)
    assert result.exposure_s == pytest.approx(film.exposure_s, rel=0.10)
    assert result.readout_ci95_s[0] <= film.readout_s <= result.readout_ci95_s[1]
    assert result.exposure_ci95_s[0] <= film.exposure_s <= result.exposure_ci95_s[1]
    assert result.fps == pytest.approx(film.fps, rel=1e-9)
    assert not result.global_shutter and result.readout_direction == "top-down"
    assert result.warnings == ()


# (fps, readout and exposure as shares of the frame interval): short and whole-frame exposures,
# readouts from a third of the frame interval to nearly all of it (4 to 30 ms).
CASES = [
    (30, 0.9, 1.0),
    (30, 0.5, 0.2),
    (60, 0.6, 0.5),
    (60, 0.9, 0.1),
    (120, 0.5, 1.0),
    (120, 0.9, 0.25),
    (240, 0.95, 0.5),
    (240, 0.95, 1.0),
]


@pytest.mark.parametrize("fps, readout_share, exposure_share", CASES)
@pytest.mark.parametrize("duty", [0.5, 0.25])
def test_readout_and_exposure_from_30_to_240_fps(flash_film, fps, readout_share, exposure_share, duty):
    exposure = exposure_share / fps
    flash = suggest_flash_hz(fps, exposure, duty)
    film = flash_film(
        fps=fps, readout_s=readout_share / fps, exposure_s=exposure, flash_hz=flash, duty=duty,
        duration_s=max(60 / fps, 12 / flash), noise_dn=2.0, vignette=0.3, seed=fps,
    )  # fmt: skip
    assert_within(measure(film, duty), film)
