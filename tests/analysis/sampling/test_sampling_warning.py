"""The display-sampling warning a lab reads: one line of cause, one of remedy (`analysis.caveat`),
never contradicting the camera it describes."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.caveat import REMEDY, caveat
from analysis.sampling import SamplingBias, suggested_fps, walks
from analysis.sampling.exposure import Exposure
from analysis.sampling.model import commensurate
from analysis.sampling.rates import COMMON_REFRESH_HZ

UNSEEN = dict(
    refresh_hz=60.0, refresh_source="not seen", rates_hz=(60.0, 59.9998, 240.0), worst_hz=240.0,
    exposure=Exposure(3.2e-3, 4.17e-3, "LED blur"), camera_fps=240.0, correction_s=0.0,
    range_s=(-0.48e-3, 0.48e-3), hypotheses=(),
)  # fmt: skip
WIDENED = ((0.040, 0.041), (0.0395, 0.0415))


def _lines(warning: str | None) -> tuple[str, str]:
    assert warning is not None
    cause, remedy = warning.split("\n")
    assert remedy.startswith(REMEDY)
    return cause, remedy.removeprefix(REMEDY)


def test_a_refresh_the_video_does_not_show_is_warned_with_each_allowed_rate_once() -> None:
    """240 fps on a display whose steps do not stand out: two tuned 60 Hz rates are one rate to a lab."""
    cause, remedy = _lines(SamplingBias(**UNSEEN).warning(*WIDENED))
    assert "60 or 240 Hz" in cause and "-0.48 to +0.48 ms" in cause
    assert remedy == (
        "give --display-hz and --exposure-ms, film at 239 fps (no common display rate is a simple fraction of it) "
        "or expose for a whole number of refreshes (4.17 ms at 240 Hz)"
    )


def test_a_camera_is_never_told_to_expose_longer_than_its_frame_interval() -> None:
    """A 240 fps camera on a 60 Hz display cannot expose for a refresh (16.7 ms)."""
    seen = SamplingBias(**{**UNSEEN, "refresh_source": "seen in the video", "rates_hz": (60.0,), "worst_hz": 60.0})
    _, remedy = _lines(seen.warning(*WIDENED))
    assert "expose for" not in remedy and "--display-hz" not in remedy and "--exposure-ms" in remedy


def test_a_camera_that_already_walks_through_the_refresh_is_not_told_to() -> None:
    walking = SamplingBias(**{**UNSEEN, "camera_fps": 239.0})
    _, remedy = _lines(walking.warning(*WIDENED))
    assert "film at" not in remedy


def test_a_corrected_bias_says_by_how_much_and_what_to_do() -> None:
    corrected = SamplingBias(**{**UNSEEN, "refresh_source": "given", "correction_s": 0.4e-3})
    cause, remedy = _lines(corrected.warning((0.040, 0.0402), None))
    assert "+0.40 ms off, and was corrected" in cause and "film at 239 fps" in remedy


@given(st.floats(min_value=1.0, max_value=10000.0))
def test_the_rate_suggested_walks_through_every_common_display_rate(camera_fps: float) -> None:
    suggested = suggested_fps(camera_fps)
    assert walks(suggested) and suggested != round(camera_fps)
    assert all(commensurate(suggested / rate, 10) is None for rate in COMMON_REFRESH_HZ)
    assert abs(suggested - camera_fps) <= max(0.1 * camera_fps, 12.0)


def test_a_caveat_is_two_lines_or_refused() -> None:
    assert caveat("the cause", "the remedy") == f"the cause\n{REMEDY}the remedy"
    for cause, remedy in (("two\nlines", "remedy"), ("cause", ""), ("", "remedy")):
        with pytest.raises(ValueError):
            caveat(cause, remedy)


def test_a_frame_rate_measured_from_a_film_is_told_as_the_rate_it_is() -> None:
    assert not walks(119.9999) and not walks(120.0001)
    locked = SamplingBias(**{**UNSEEN, "camera_fps": 119.9999, "refresh_source": "given", "rates_hz": (60.0,), "worst_hz": 60.0,
                             "exposure": Exposure(4e-3, 4e-3, "given")})  # fmt: skip
    _, remedy = _lines(locked.warning(*WIDENED))
    assert remedy == "film at 118 fps (no common display rate is a simple fraction of it)"
