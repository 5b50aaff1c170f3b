"""The display-sampling warning a lab reads: one cause and its remedies, never contradicting the
camera it describes."""

from __future__ import annotations

from analysis.sampling import SamplingBias
from analysis.sampling.exposure import Exposure


def test_a_refresh_the_video_does_not_show_is_warned_with_each_allowed_rate_once() -> None:
    """240 fps on a display whose steps do not stand out: the camera is faster than any 60 Hz
    display, so the warning must not say it is not; two tuned 60 Hz rates are one rate to a lab."""
    bias = SamplingBias(
        refresh_hz=60.0, refresh_source="not seen", rates_hz=(60.0, 59.9998, 240.0), worst_hz=240.0,
        exposure=Exposure(3.2e-3, 4.17e-3, "LED blur"), camera_fps=240.0, correction_s=0.0,
        range_s=(-0.48e-3, 0.48e-3), hypotheses=(),
    )  # fmt: skip
    warning = bias.warning((0.040, 0.041), (0.0395, 0.0415))
    assert "not faster than the display" not in warning
    assert "allows 60, 240 Hz" in warning and "for a 240 Hz display" in warning
    assert "-0.48 to +0.48 ms" in warning and "--display-hz" in warning and "--exposure-ms" in warning
