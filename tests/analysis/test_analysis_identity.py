"""Which blob is the LED, by physical evidence, never by brightness; a refusal when nothing decides."""

import numpy as np
import pytest

from analysis import AnalysisError, analyse, track
from analysis.identity import decide, step_score
from analysis.tracking import Roi


def centre(roi: Roi) -> float:
    return roi.x + roi.width / 2


def test_a_dim_led_beside_a_bright_sphere_is_still_the_led(scene, render_video):
    # The sphere is the brighter blob; the display's steps (240 fps on 60 Hz) say it is the sphere.
    clip = scene(latency_s=0.04, led_gain=120.0, sphere_gain=700.0, duration_s=4.1)
    result = analyse(render_video(clip), fps=clip.fps, method="fft")
    assert result.latency_ms == pytest.approx(40.0, abs=0.3)
    assert centre(result.led_roi) < clip.width / 2 < centre(result.sphere_roi)
    assert "refresh steps +" in result.led_rule


def test_an_led_on_the_right_is_found_against_the_side_convention(scene, render_video):
    clip = scene(latency_s=0.04, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0), duration_s=4.1)
    tracks = track(render_video(clip), fps=clip.fps)
    assert centre(tracks.led_roi) > clip.width / 2
    assert "side +1.0" in tracks.led_rule and "total -" in tracks.led_rule


def test_without_evidence_the_analysis_asks_for_the_regions(scene, render_video):
    # 60 fps on a 60 Hz display (no steps to see), a dim LED (no saturation) the sphere's size, the
    # LED on the right: nothing decides, so no number at all rather than a sign-flipped one.
    clip = scene(
        latency_s=0.04, fps=60.0, led_gain=150.0, led_sigma=3.0, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0),
        duration_s=4.2,
    )  # fmt: skip
    with pytest.raises(AnalysisError, match="cannot tell the LED from the sphere.*--led-roi"):
        analyse(render_video(clip), fps=clip.fps, method="fft")
    result = analyse(render_video(clip), fps=clip.fps, method="fft", led_side="right")
    assert result.latency_ms == pytest.approx(40.0, abs=0.5)


def test_continuous_motion_scores_no_steps_and_a_staircase_does():
    fps, t = 240.0, np.arange(960) / 240.0
    smooth = 80 * np.sin(2 * np.pi * t) + 0.05 * np.random.default_rng(0).standard_normal(t.size)
    held = 80 * np.sin(2 * np.pi * (np.floor(t * 60) / 60))
    assert step_score(smooth, 1 / fps, 1.0) == 0.0
    assert step_score(held, 1 / fps, 1.0) > 2.0


def test_the_decision_needs_a_margin(scene, render_video):
    clip = scene(latency_s=0.03, duration_s=3.0, fps=120.0)
    tracks = track(render_video(clip), fps=clip.fps)
    signals = (tracks.led.x - np.nanmean(tracks.led.x), tracks.sphere.x - np.nanmean(tracks.sphere.x))
    identity = decide(tracks.led, tracks.sphere, signals, 1 / clip.fps, clip.period_s)
    assert identity.first_is_led is True and identity.margin >= 3.0
    swapped = decide(tracks.sphere, tracks.led, signals[::-1], 1 / clip.fps, clip.period_s)
    assert swapped.first_is_led is False
