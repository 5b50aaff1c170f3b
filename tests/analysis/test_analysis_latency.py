"""The whole chain on synthetic pendulum videos with a known latency."""

import json
import threading

import numpy as np
import pytest

from analysis import AnalysisError, analyse

TOLERANCE_MS = 0.5


@pytest.mark.parametrize(
    ("latency_ms", "period_s", "fps", "display_hz"),
    [
        (0.0, 0.8, 240.0, 60.0),
        (0.0, 1.3, 120.0, 144.0),
        (16.7, 0.8, 120.0, 60.0),
        (16.7, 1.3, 240.0, 144.0),
        (50.0, 0.8, 240.0, 144.0),
        (50.0, 1.3, 120.0, 60.0),
        (120.0, 0.8, 120.0, 144.0),
        (120.0, 1.3, 240.0, 60.0),
    ],
)
def test_latency_is_recovered(scene, render_video, latency_ms, period_s, fps, display_hz):
    # 6.3 s holds 7.9 or 4.8 periods: never a whole number.
    clip = scene(
        latency_s=latency_ms / 1e3, period_s=period_s, fps=fps, display_hz=display_hz, duration_s=6.3
    )
    result = analyse(render_video(clip), fps=fps)
    assert result.latency_ms == pytest.approx(latency_ms, abs=TOLERANCE_MS)
    assert result.period_s == pytest.approx(period_s, rel=1e-3)
    assert result.frames == result.frames_used == clip.frame_count
    assert (result.method, result.model, result.ci95_ms, result.ambiguous) == ("fft", "sine", None, False)
    assert (result.roi_source, result.led_rule) == ("auto", "auto: brighter blob is the LED")
    assert result.warnings == []


def test_sphere_ahead_of_the_led_gives_negative_latency(scene, render_video):
    clip = scene(latency_s=-0.025, duration_s=5.2)
    assert analyse(render_video(clip), fps=clip.fps).latency_ms == pytest.approx(-25.0, abs=TOLERANCE_MS)


def test_mjpg_video_file(tmp_path, scene, render_video, mjpg_file):
    clip = scene(latency_s=0.033, period_s=0.9, duration_s=5.3)
    path = mjpg_file(tmp_path / "pendulum.avi", render_video(clip), clip.fps)
    result = analyse(path)
    assert result.latency_ms == pytest.approx(33.0, abs=TOLERANCE_MS)
    assert result.fps == clip.fps
    assert result.frames == clip.frame_count


@pytest.mark.parametrize("form", ["float", "bgr"])
def test_frames_as_float_or_colour_arrays(scene, render_video, form):
    clip = scene(latency_s=0.07, duration_s=4.1)
    grey = render_video(clip)
    frames = grey / 255.0 if form == "float" else np.repeat(grey[..., None], 3, axis=3)
    assert analyse(frames, fps=clip.fps).latency_ms == pytest.approx(70.0, abs=TOLERANCE_MS)


def test_failed_analysis_of_a_file_leaves_no_decoder_threads(tmp_path, scene, render_video, mjpg_file):
    clip = scene(led_moves=False, duration_s=2.0)
    path = mjpg_file(tmp_path / "still.avi", render_video(clip), clip.fps)
    before = threading.active_count()
    try:
        analyse(path)
    except AnalysisError as error:
        # Checked while the traceback still holds the analyser's frame and its frame stream.
        assert "moving bright region" in str(error)
        assert threading.active_count() == before
    else:
        pytest.fail("a video in which nothing moves was analysed")


def test_led_on_the_right_is_told_by_its_brightness(scene, render_video, scene_truth):
    clip = scene(latency_s=0.04, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0), duration_s=5.2)
    result = analyse(render_video(clip), fps=clip.fps)
    assert result.latency_ms == pytest.approx(40.0, abs=TOLERANCE_MS)
    led_x, _, sphere_x, _ = scene_truth(clip)
    assert result.led_roi.x < led_x.min() and led_x.max() < result.led_roi.x + result.led_roi.width
    assert (
        result.sphere_roi.x < sphere_x.min()
        and sphere_x.max() < result.sphere_roi.x + result.sphere_roi.width
    )


def test_equally_bright_blobs_take_the_left_as_the_led(scene, render_video):
    clip = scene(latency_s=0.03, sphere_gain=700.0, panel=12.0, duration_s=4.1)
    result = analyse(render_video(clip), fps=clip.fps)
    assert result.latency_ms == pytest.approx(30.0, abs=TOLERANCE_MS)
    assert result.led_rule == "auto: blobs equally bright, left blob is the LED"
    assert result.led_roi.x < result.sphere_roi.x
    assert any("equally bright" in warning for warning in result.warnings)


def test_given_rois_are_used(scene, render_video, scene_truth):
    clip = scene(latency_s=0.06, duration_s=5.2)
    led_roi, sphere_roi = [2, 30, 76, 40], [80, 30, 78, 45]
    result = analyse(render_video(clip), fps=clip.fps, led_roi=led_roi, sphere_roi=sphere_roi)
    assert result.latency_ms == pytest.approx(60.0, abs=TOLERANCE_MS)
    assert (result.led_roi.as_list(), result.sphere_roi.as_list()) == (led_roi, sphere_roi)
    assert (result.roi_source, result.led_rule) == ("given", "given")


def test_frames_without_sphere_are_interpolated_and_reported(scene, render_video):
    clip = scene(latency_s=0.05, duration_s=5.2)
    frames = render_video(clip).copy()
    hidden = np.random.default_rng(7).choice(
        clip.frame_count, size=clip.frame_count * 3 // 100, replace=False
    )
    frames[hidden, :, 80:] = 21
    result = analyse(frames, fps=clip.fps)
    assert result.latency_ms == pytest.approx(50.0, abs=TOLERANCE_MS)
    assert result.frames_used == clip.frame_count - hidden.size
    assert not result.sphere_track.valid[hidden].any()
    assert result.warnings == [
        f"the sphere was missing in {hidden.size} frames (3.0%); its position there was interpolated"
    ]


def test_latency_near_half_a_period_is_flagged(scene, render_video):
    clip = scene(latency_s=0.46, period_s=1.0, duration_s=5.2)
    result = analyse(render_video(clip), fps=clip.fps)
    assert result.latency_ms == pytest.approx(460.0, abs=TOLERANCE_MS)
    assert result.ambiguous
    assert any("half the period" in warning for warning in result.warnings)


def test_progress_is_reported_up_to_the_last_frame(scene, render_video):
    clip = scene(duration_s=2.5)
    calls = []
    analyse(render_video(clip), fps=clip.fps, progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (clip.frame_count, clip.frame_count)
    assert all(total == clip.frame_count for _, total in calls)
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)


def test_summary_is_json_ready(scene, render_video):
    clip = scene(latency_s=0.02, duration_s=2.5)
    summary = analyse(render_video(clip), fps=clip.fps).to_dict()
    assert json.loads(json.dumps(summary)) == summary
    assert summary["latency_ms"] == pytest.approx(20.0, abs=TOLERANCE_MS)
    assert set(summary) >= {
        "latency_ms",
        "ci95_ms",
        "method",
        "model",
        "period_s",
        "frames",
        "frames_used",
        "ambiguous",
        "warnings",
        "led_roi",
        "sphere_roi",
        "roi_source",
        "led_rule",
    }


def test_roi_outside_the_frame_raises(scene, render_video):
    clip = scene(duration_s=2.5)
    with pytest.raises(AnalysisError, match="outside the frame"):
        analyse(render_video(clip), fps=clip.fps, led_roi=[150, 30, 40, 40], sphere_roi=[80, 30, 78, 45])


def test_only_one_roi_raises(scene, render_video):
    clip = scene(duration_s=2.5)
    with pytest.raises(AnalysisError, match="give both"):
        analyse(render_video(clip), fps=clip.fps, led_roi=[2, 30, 76, 40])


@pytest.mark.parametrize(
    "rois", [{}, {"led_roi": [2, 30, 76, 40], "sphere_roi": [80, 30, 78, 45]}], ids=["auto", "given"]
)
def test_static_led_raises(scene, render_video, rois):
    clip = scene(led_moves=False, duration_s=3.0)
    with pytest.raises(AnalysisError, match="moving"):
        analyse(render_video(clip), fps=clip.fps, **rois)


def test_sphere_never_drawn_raises(scene, render_video):
    clip = scene(sphere_gain=0.0, duration_s=3.0)
    with pytest.raises(AnalysisError, match="found 1 moving"):
        analyse(render_video(clip), fps=clip.fps)


def test_clip_shorter_than_two_periods_raises(scene, render_video):
    clip = scene(period_s=1.0, duration_s=1.6)
    with pytest.raises(AnalysisError, match="periods"):
        analyse(render_video(clip), fps=clip.fps)
