"""Which blob is the LED, by physical evidence, never by brightness; a refusal when nothing decides."""

import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions, analyse, track
from analysis.identity import SATURATION_WEIGHT, decide, step_score
from analysis.blobs import Roi
from rig.cli import EXIT_USER_ERROR, main

# 60 fps on a 60 Hz display (no steps to see), a dim LED (no saturation) the sphere's size, the LED
# on the right: nothing physical says which blob is which.
UNDECIDABLE = {
    "latency_s": 0.04, "fps": 60.0, "led_gain": 150.0, "led_sigma": 3.0, "led_centre": (115.0, 55.0),
    "sphere_centre": (40.0, 60.0), "duration_s": 4.2,
}  # fmt: skip
# Regions holding each blob's whole swing in that scene ([x, y, width, height]).
UNDECIDABLE_LED_ROI = [78, 38, 78, 28]
UNDECIDABLE_SPHERE_ROI = [4, 44, 72, 28]


def centre(roi: Roi) -> float:
    return roi.x + roi.width / 2


def decided(clip, render_video, led_side=None):
    """Both blobs' tracks in ``clip`` (the LED's side given where the evidence cannot tell), and the
    decision on them in either order: the LED first, then the sphere first."""
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps, led_side=led_side))
    signals = (tracks.led.x - np.nanmean(tracks.led.x), tracks.sphere.x - np.nanmean(tracks.sphere.x))
    as_given = decide(tracks.led, tracks.sphere, signals, 1 / clip.fps, clip.period_s)
    swapped = decide(tracks.sphere, tracks.led, signals[::-1], 1 / clip.fps, clip.period_s)
    return tracks, as_given, swapped


def test_a_dim_led_beside_a_bright_sphere_is_still_the_led(scene, render_video):
    # The sphere is the brighter blob; the display's steps (240 fps on 60 Hz) say it is the sphere.
    clip = scene(latency_s=0.04, led_gain=120.0, sphere_gain=700.0, duration_s=4.1)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"))
    assert result.latency_ms == pytest.approx(40.0, abs=0.3)
    assert centre(result.led_roi) < clip.width / 2 < centre(result.sphere_roi)
    assert "refresh steps +" in result.led_rule


def test_an_led_on_the_right_is_found_against_the_side_convention(scene, render_video):
    clip = scene(latency_s=0.04, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0), duration_s=4.1)
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert centre(tracks.led_roi) > clip.width / 2
    assert "side +1.0" in tracks.led_rule and "total -" in tracks.led_rule


def test_without_evidence_the_analysis_asks_for_the_regions(scene, render_video):
    # Nothing decides, so no number at all rather than a sign-flipped one.
    clip = scene(**UNDECIDABLE)
    with pytest.raises(AnalysisError, match="cannot tell the LED from the sphere.*--led-roi"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"))
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft", led_side="right"))
    assert result.latency_ms == pytest.approx(40.0, abs=0.5)


def test_continuous_motion_scores_no_steps_and_a_staircase_does():
    fps, t = 240.0, np.arange(960) / 240.0
    smooth = 80 * np.sin(2 * np.pi * t) + 0.05 * np.random.default_rng(0).standard_normal(t.size)
    held = 80 * np.sin(2 * np.pi * (np.floor(t * 60) / 60))
    assert step_score(smooth, 1 / fps, 1.0) == 0.0
    assert step_score(held, 1 / fps, 1.0) > 2.0


def test_the_decision_needs_a_margin(scene, render_video):
    _, identity, swapped = decided(scene(latency_s=0.03, duration_s=3.0, fps=120.0), render_video)
    assert identity.first_is_led is True and identity.margin >= 3.0
    assert swapped.first_is_led is False


def test_the_undecidable_refusal_exits_2_asking_for_the_regions(tmp_path, scene, render_video, mjpg_file, capsys):
    clip = scene(**UNDECIDABLE)
    video = mjpg_file(tmp_path / "clip.avi", render_video(clip), clip.fps)
    assert main(["analyse", str(video)]) == EXIT_USER_ERROR == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    error = captured.err.strip()
    assert len(error.splitlines()) == 1 and "Traceback" not in error
    assert "cannot tell the LED from the sphere" in error and "--led-roi" in error and "--sphere-roi" in error


def test_the_users_regions_decide_where_the_evidence_cannot(scene, render_video):
    # The same undecidable scene: the regions the user gives are taken as given, with no vote.
    clip = scene(**UNDECIDABLE)
    result = analyse(
        render_video(clip), AnalysisOptions(fps=clip.fps, method="fft", led_roi=UNDECIDABLE_LED_ROI, sphere_roi=UNDECIDABLE_SPHERE_ROI)
    )
    assert result.roi_source == "given"
    assert result.latency_ms == pytest.approx(40.0, abs=0.5)
    assert centre(result.led_roi) > clip.width / 2 > centre(result.sphere_roi)


def test_the_users_regions_overrule_the_evidence(scene, render_video):
    # The evidence (steps, saturation, size, side) all say the left blob is the LED; regions given
    # the other way round are still what is measured: the latency comes out negative, not corrected.
    clip = scene(latency_s=0.03, duration_s=3.0, fps=120.0)
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps))
    led, sphere = tracks.led_roi, tracks.sphere_roi
    swapped = track(render_video(clip), AnalysisOptions(
        fps=clip.fps, led_roi=[sphere.x, sphere.y, sphere.width, sphere.height], sphere_roi=[led.x, led.y, led.width, led.height],
    ))  # fmt: skip
    assert swapped.roi_source == "given"
    assert centre(swapped.led_roi) > clip.width / 2 > centre(swapped.sphere_roi)


def test_a_point_like_led_counts_as_smaller_than_the_drawn_sphere(scene, render_video):
    # The default scene: LED sigma 1.8 px, sphere sigma 3 px.
    _, as_given, swapped = decided(scene(latency_s=0.03, duration_s=3.0, fps=120.0), render_video)
    assert as_given.evidence["size"] > 0.3
    assert swapped.evidence["size"] == pytest.approx(-as_given.evidence["size"])


def test_blobs_of_one_size_say_nothing_by_size(scene, render_video):
    _, as_given, _ = decided(scene(**UNDECIDABLE), render_video, led_side="right")
    assert abs(as_given.evidence["size"]) < 0.15


def test_a_saturating_led_beside_an_unsaturated_sphere_is_named_by_saturation(scene, render_video):
    tracks, as_given, swapped = decided(scene(latency_s=0.03, duration_s=3.0, fps=120.0), render_video)
    assert np.mean(tracks.led.level[tracks.led.valid] >= 250) > 0.5
    assert as_given.evidence["saturation"] == SATURATION_WEIGHT
    assert swapped.evidence["saturation"] == -SATURATION_WEIGHT


def test_saturation_says_nothing_when_neither_blob_saturates(scene, render_video):
    _, as_given, _ = decided(scene(**UNDECIDABLE), render_video, led_side="right")
    assert as_given.evidence["saturation"] == 0.0
