"""The whole chain on synthetic pendulum videos with a known latency: a grid, and one test per hard case."""

import json
import math
import threading

import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions, analyse
from analysis.plots import plot_tracks
from analysis.blobs import Track
from analysis.tracks import check_track

EVIDENCE_RULE = "auto: by physical evidence"
# sinefit's error on these clean clips stays far below a tenth of a camera frame...
FRAMES_TOLERANCE = 0.1
# ...and the other methods' within a third of one.
OTHER_METHODS_FRAMES = 0.35

# (latency ms, period s, camera fps, display Hz, decay over the clip, seconds): 32 cases, none of
# them a whole number of periods, latencies from -40 to 480 ms.
GRID = [
    (latency, period, fps, display, decay, seconds)
    for latency, period, fps, display, decay, seconds in [
        (0.0, 0.8, 120.0, 60.0, 0.2, 4.1),
        (0.0, 1.3, 240.0, 144.0, 0.0, 4.3),
        (8.3, 0.7, 60.0, 90.0, 0.4, 4.6),
        (16.7, 0.8, 120.0, 60.0, 0.2, 4.1),
        (16.7, 1.3, 240.0, 144.0, 0.1, 4.3),
        (25.0, 1.1, 60.0, 60.0, 0.3, 4.5),
        (33.3, 0.9, 120.0, 90.0, 0.0, 3.7),
        (41.0, 1.2, 240.0, 60.0, 0.5, 4.9),
        (50.0, 0.8, 240.0, 144.0, 0.2, 4.1),
        (50.0, 1.3, 120.0, 60.0, 0.2, 4.3),
        (66.7, 0.6, 60.0, 144.0, 0.3, 3.7),
        (75.0, 1.0, 120.0, 90.0, 0.1, 4.2),
        (90.0, 0.7, 240.0, 60.0, 0.2, 3.9),
        (100.0, 1.25, 60.0, 120.0, 0.4, 4.4),
        (120.0, 0.8, 120.0, 144.0, 0.2, 4.1),
        (120.0, 1.3, 240.0, 60.0, 0.2, 4.3),
        (150.0, 0.9, 60.0, 60.0, 0.0, 4.0),
        (175.0, 1.15, 120.0, 120.0, 0.3, 4.6),
        (200.0, 1.0, 240.0, 90.0, 0.2, 3.3),
        (220.0, 1.3, 60.0, 60.0, 0.1, 4.7),
        (250.0, 0.95, 120.0, 144.0, 0.5, 4.1),
        (280.0, 1.2, 240.0, 60.0, 0.2, 3.9),
        (300.0, 1.05, 120.0, 90.0, 0.2, 4.4),
        (330.0, 1.3, 60.0, 144.0, 0.3, 4.2),
        (360.0, 1.2, 120.0, 60.0, 0.1, 3.7),
        (400.0, 1.25, 240.0, 120.0, 0.2, 4.0),
        (450.0, 1.3, 120.0, 60.0, 0.4, 4.5),
        (480.0, 1.3, 60.0, 90.0, 0.2, 4.1),
        (-10.0, 0.85, 120.0, 60.0, 0.2, 4.2),
        (-25.0, 1.0, 240.0, 144.0, 0.3, 4.3),
        (-40.0, 1.2, 60.0, 60.0, 0.1, 4.4),
        (5.0, 1.3, 120.0, 60.0, 0.6, 4.7),
    ]
]


# Every camera and display rate of the grid is commensurate, so how the exposures sample the refreshes
# depends on the exposure: the grid gives the camera's settings, as a lab that knows them does
# (--display-hz, --exposure-ms, and --readout-ms 0 for its global shutter). Without them the interval
# widens (see test_analysis_sampling and test_analysis_shutter).
@pytest.mark.parametrize(("latency_ms", "period_s", "fps", "display_hz", "decay", "seconds"), GRID)
def test_latency_is_recovered_on_the_grid(scene, render_video, latency_ms, period_s, fps, display_hz, decay, seconds):
    clip = scene(
        latency_s=latency_ms / 1e3, period_s=period_s, fps=fps, display_hz=display_hz, decay=decay, duration_s=seconds
    )
    known = AnalysisOptions(fps=fps, display_hz=display_hz, exposure_ms=clip.exposure * 1e3 / fps, readout_ms=0.0)
    result = analyse(render_video(clip), known)
    frame_ms = 1e3 / fps
    assert result.latency_ms == pytest.approx(latency_ms, abs=FRAMES_TOLERANCE * frame_ms)
    assert result.ci95_ms[0] < result.latency_ms < result.ci95_ms[1]
    assert result.ci95_ms[1] - result.ci95_ms[0] < 0.5 * frame_ms
    assert result.period_s == pytest.approx(period_s, rel=2e-3)
    assert result.frames == result.frames_used == clip.frame_count
    assert (result.method, result.ambiguous, result.warnings) == ("sinefit", False, [])
    assert result.roi_source == "auto" and result.led_rule.startswith(EVIDENCE_RULE)


def test_every_method_agrees_on_one_clip(tmp_path, scene, render_video):
    clip = scene(latency_s=0.083, period_s=0.9, fps=120.0, duration_s=4.3)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="all"))
    assert plot_tracks(result, tmp_path / "all.png").stat().st_size > 10_000
    assert list(result.methods) == ["fft", "xcorr", "sinefit", "bayes"]
    assert result.method == "sinefit"
    for name, estimate in result.methods.items():
        tolerance = FRAMES_TOLERANCE if name in ("sinefit", "bayes") else OTHER_METHODS_FRAMES
        assert estimate.latency_ms == pytest.approx(83.0, abs=tolerance * 1e3 / clip.fps), name
    bayes = result.methods["bayes"]
    assert bayes.ci95_ms[0] < 83.0 < bayes.ci95_ms[1]
    assert {"autocorrelation_steps", "acceptance_fraction"} <= set(bayes.details)
    summary = json.loads(json.dumps(result.to_dict()))
    assert set(summary["methods"]) == {"fft", "xcorr", "sinefit", "bayes"}


def test_non_integer_number_of_swings(scene, render_video):
    clip = scene(latency_s=0.061, period_s=1.1, duration_s=4.37 * 1.1, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(61.0, abs=0.3)


def test_strongly_damped_swing(scene, render_video):
    clip = scene(latency_s=0.045, decay=0.75, period_s=0.8, duration_s=4.4, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(45.0, abs=0.3)
    assert result.model.startswith("damped")


def test_wide_swing_with_harmonics(scene, render_video):
    clip = scene(latency_s=0.07, swing_rad=0.75, arm_px=45.0, chirp=True, decay=0.3, duration_s=4.3, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(70.0, abs=0.3)
    assert "harmonics" in result.model


@pytest.mark.parametrize(
    "blur", [{"defocus_px": 2.0}, {"period_s": 0.6, "swing_rad": 0.6, "arm_px": 50.0}], ids=["defocus", "motion"]
)
def test_blurred_blobs(scene, render_video, blur):
    clip = scene(latency_s=0.05, duration_s=4.2, fps=60.0, **blur)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(50.0, abs=0.5)


def test_saturated_led_with_bloom(scene, render_video):
    clip = scene(latency_s=0.05, led_gain=3000.0, bloom_gain=400.0, duration_s=4.2, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(50.0, abs=0.3)


def test_dim_sphere_next_to_a_bright_led(scene, render_video):
    clip = scene(latency_s=0.05, sphere_gain=22.0, led_gain=3000.0, duration_s=4.2, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(50.0, abs=0.5)
    assert result.led_rule.startswith(EVIDENCE_RULE)


def test_static_bright_clutter_in_both_regions(scene, render_video):
    clutter = ((40.0, 45.0, 600.0), (30.0, 58.0, 200.0), (118.0, 55.0, 300.0), (100.0, 62.0, 150.0))
    clip = scene(latency_s=0.05, clutter=clutter, duration_s=4.2, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(50.0, abs=0.3)
    assert result.frames_used == clip.frame_count


def test_missing_detections_are_left_out_and_reported(scene, render_video):
    clip = scene(latency_s=0.05, duration_s=4.2, fps=120.0)
    frames = render_video(clip).copy()
    hidden = np.random.default_rng(7).choice(clip.frame_count, size=clip.frame_count * 5 // 100, replace=False)
    frames[hidden, :, 80:] = 21
    result = analyse(frames, AnalysisOptions(fps=clip.fps, display_hz=clip.display_hz, exposure_ms=1e3 / clip.fps, readout_ms=0.0))
    assert result.latency_ms == pytest.approx(50.0, abs=0.3)
    assert result.frames_used == clip.frame_count - hidden.size
    assert not result.sphere_track.valid[hidden].any()
    assert result.warnings == [
        f"the sphere was missing in {hidden.size} frames (5.0%), of them {hidden.size} dark (off or hidden); "
        "those frames were left out\nto avoid it: keep the sphere lit and in view while filming"
    ]
    assert result.diagnostics["detection_rate"]["sphere"] == pytest.approx(0.95, abs=0.005)


def test_beyond_half_a_period_resolved_by_the_chirp(scene, render_video):
    # 450 ms with a 0.6 s pendulum: the phase says -150 ms; the decaying, chirping swing says 450.
    clip = scene(
        latency_s=0.45, period_s=0.6, swing_rad=0.7, arm_px=45.0, chirp=True, decay=0.85, duration_s=5.5, fps=60.0
    )
    for method in ("fft", "xcorr", "sinefit"):
        result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method=method))
        assert not result.ambiguous
        assert result.cycles.how == "chirp"
        assert result.latency_ms == pytest.approx(450.0, abs=1.5), method


def test_beyond_half_a_period_unresolvable_is_ambiguous(scene, render_video):
    clip = scene(latency_s=0.45, period_s=0.6, decay=0.05, duration_s=5.5, fps=60.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.ambiguous
    assert result.cycles.candidates_s == pytest.approx([-0.15, 0.45], abs=2e-3)
    assert result.latency_ms == pytest.approx(-150.0, abs=1.0)
    assert any("known only modulo the swing period" in w for w in result.warnings)


def test_negative_latency_of_an_over_predicting_system(scene, render_video):
    clip = scene(latency_s=-0.025, duration_s=4.2, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(-25.0, abs=0.3)
    assert result.ci95_ms[0] < -25.0 < result.ci95_ms[1]


def test_latency_near_half_the_period(scene, render_video):
    # 490 ms of a 1 s period: the wrapped phase is next to its jump; the range keeps it a lag.
    clip = scene(latency_s=0.49, period_s=1.0, duration_s=4.3, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps))
    assert result.latency_ms == pytest.approx(490.0, abs=0.3)
    assert not result.ambiguous and result.cycles.how == "range"


def test_mjpg_video_file(tmp_path, scene, render_video, mjpg_file):
    clip = scene(latency_s=0.033, period_s=0.9, duration_s=4.3, fps=120.0)
    path = mjpg_file(tmp_path / "pendulum.avi", render_video(clip), clip.fps)
    result = analyse(path)
    assert result.latency_ms == pytest.approx(33.0, abs=0.3)
    assert result.fps == clip.fps
    assert result.frames == clip.frame_count
    assert result.diagnostics["time_source"] == "container timestamps"


@pytest.mark.parametrize("form", ["float", "bgr"])
def test_frames_as_float_or_colour_arrays(scene, render_video, form):
    clip = scene(latency_s=0.07, duration_s=4.1, fps=120.0)
    grey = render_video(clip)
    frames = grey / 255.0 if form == "float" else np.repeat(grey[..., None], 3, axis=3)
    assert analyse(frames, AnalysisOptions(fps=clip.fps, method="fft")).latency_ms == pytest.approx(70.0, abs=0.5)


def test_failed_analysis_of_a_file_leaves_no_decoder_threads(tmp_path, scene, render_video, mjpg_file):
    clip = scene(led_moves=False, duration_s=2.0, fps=120.0)
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


def test_led_on_the_right_is_told_by_the_evidence(scene, render_video, scene_truth):
    clip = scene(latency_s=0.04, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0), duration_s=4.2, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"))
    assert result.latency_ms == pytest.approx(40.0, abs=0.5)
    led_x, _, sphere_x, _ = scene_truth(clip)
    assert result.led_roi.x < led_x.min() and led_x.max() < result.led_roi.x + result.led_roi.width
    assert result.sphere_roi.x < sphere_x.min() and sphere_x.max() < result.sphere_roi.x + result.sphere_roi.width


def test_equally_bright_blobs_are_told_apart_by_the_refresh_steps(scene, render_video):
    clip = scene(latency_s=0.03, sphere_gain=700.0, panel=12.0, duration_s=4.1, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"))
    assert result.latency_ms == pytest.approx(30.0, abs=0.5)
    assert result.led_rule.startswith(EVIDENCE_RULE) and "refresh steps +" in result.led_rule


def test_the_user_says_which_side_the_led_is_on(scene, render_video):
    clip = scene(latency_s=0.03, led_centre=(115.0, 55.0), sphere_centre=(40.0, 60.0), sphere_gain=700.0,
                 led_gain=150.0, duration_s=4.1, fps=120.0)  # fmt: skip
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft", led_side="right"))
    assert result.led_rule == "given: right blob is the LED"
    assert result.latency_ms == pytest.approx(30.0, abs=0.5)


def test_given_rois_are_used(scene, render_video):
    clip = scene(latency_s=0.06, duration_s=4.2, fps=120.0)
    led_roi, sphere_roi = [2, 30, 76, 40], [80, 30, 78, 45]
    result = analyse(render_video(clip), AnalysisOptions(fps=clip.fps, led_roi=led_roi, sphere_roi=sphere_roi, method="fft"))
    assert result.latency_ms == pytest.approx(60.0, abs=0.5)
    assert (result.led_roi.as_list(), result.sphere_roi.as_list()) == (led_roi, sphere_roi)
    assert (result.roi_source, result.led_rule) == ("given", "given")


def test_progress_is_reported_up_to_the_last_frame(scene, render_video):
    clip = scene(duration_s=4.1, fps=120.0)
    calls = []
    analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"), progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (clip.frame_count, clip.frame_count)
    assert all(total == clip.frame_count for _, total in calls)
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)


def test_a_short_clip_reports_no_progress(scene, render_video):
    clip = scene(duration_s=2.5, fps=120.0)
    calls = []
    analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"), progress=lambda done, total: calls.append(done))
    assert calls == []


def test_summary_is_json_ready_and_carries_the_contract(scene, render_video):
    clip = scene(latency_s=0.02, duration_s=4.1, fps=120.0)
    summary = analyse(render_video(clip), AnalysisOptions(fps=clip.fps)).to_dict()
    assert json.loads(json.dumps(summary)) == summary
    assert summary["latency_ms"] == pytest.approx(20.0, abs=0.3)
    assert set(summary) >= {
        "latency_ms", "ci95_ms", "method", "model", "period_s", "frames", "frames_used", "ambiguous", "warnings",
        "led_roi", "sphere_roi", "roi_source", "led_rule", "methods", "windowed", "diagnostics", "cycles",
    }  # fmt: skip
    assert set(summary["methods"]["sinefit"]) >= {"latency_ms", "ci95_ms", "se_ms", "residual_rms_px", "model"}
    assert set(summary["windowed"]) >= {"mean_ms", "sd_ms", "count", "latency_ms"}
    assert set(summary["diagnostics"]["detection_rate"]) == {"led", "sphere"}


# Bad input: a one-line AnalysisError each (the command line turns it into exit status 2).


def test_roi_outside_the_frame_raises(scene, render_video):
    clip = scene(duration_s=2.5, fps=120.0)
    with pytest.raises(AnalysisError, match="outside the frame"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, led_roi=[150, 30, 40, 40], sphere_roi=[80, 30, 78, 45]))


def test_only_one_roi_raises(scene, render_video):
    clip = scene(duration_s=2.5, fps=120.0)
    with pytest.raises(AnalysisError, match="give both"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, led_roi=[2, 30, 76, 40]))


@pytest.mark.parametrize(
    "rois", [{}, {"led_roi": [2, 30, 76, 40], "sphere_roi": [80, 30, 78, 45]}], ids=["auto", "given"]
)
def test_led_that_never_moves_raises(scene, render_video, rois):
    clip = scene(led_moves=False, duration_s=3.0, fps=120.0)
    with pytest.raises(AnalysisError, match="moving"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, **rois))


def test_only_one_blob_raises(scene, render_video):
    clip = scene(sphere_gain=0.0, duration_s=3.0, fps=120.0)
    with pytest.raises(AnalysisError, match="found 1 moving"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps))


def test_sphere_that_leaves_its_region_raises(scene, render_video):
    clip = scene(duration_s=3.0, fps=120.0)
    with pytest.raises(AnalysisError, match="sphere leaves its ROI"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, led_roi=[2, 30, 76, 40], sphere_roi=[100, 30, 30, 45]))


def test_fewer_than_two_swings_raise(scene, render_video):
    clip = scene(period_s=1.0, duration_s=1.6, fps=120.0)
    with pytest.raises(AnalysisError, match="periods"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps))


def test_unknown_method_and_bad_range_raise(scene, render_video):
    frames = render_video(scene(duration_s=2.5, fps=120.0))
    with pytest.raises(AnalysisError, match="method must be one of fft, xcorr, sinefit, bayes, all, got 'guess'"):
        analyse(frames, AnalysisOptions(fps=120.0, method="guess"))
    with pytest.raises(AnalysisError, match="latency_range_ms: LOW must be below HIGH"):
        analyse(frames, AnalysisOptions(fps=120.0, latency_range_ms=(100.0, -100.0)))
    with pytest.raises(AnalysisError, match="led_side must be one of left, right"):
        analyse(frames, AnalysisOptions(fps=120.0, led_side="top"))


def test_wrong_frame_rate_gives_an_implausible_period_warning(scene, render_video):
    # A slow-motion file played back at an eighth of its capture rate.
    clip = scene(latency_s=0.05, period_s=0.8, duration_s=4.1, fps=120.0)
    result = analyse(render_video(clip), AnalysisOptions(fps=15.0, method="fft"))
    assert result.period_s == pytest.approx(6.4, rel=1e-2)
    assert any("slow motion" in w for w in result.warnings)
    assert math.isfinite(result.latency_ms)


def test_missing_frames_are_told_apart_as_dark_or_cut_off():
    # A blink code switches the LED off (dark); a blob at the ROI's edge is cut off; a blob seen
    # but not measurable is neither.
    valid = np.ones(200, dtype=bool)
    valid[[10, 11, 12, 50, 51, 120]] = False
    clipped = np.zeros(200, dtype=bool)
    clipped[[50, 51]] = True
    peak = np.full(200, 250.0)
    peak[[10, 11, 12]] = 3.0
    track = Track(np.arange(200) / 100, np.where(valid, 1.0, np.nan), np.where(valid, 1.0, np.nan), valid, peak, clipped)
    warnings = []
    check_track(track, "LED", warnings)
    assert warnings == [
        "the LED was missing in 6 frames (3.0%), of them 3 dark (off or hidden) and 2 cut off by the ROI's edge; "
        "those frames were left out\nto avoid it: keep the LED lit and in view while filming, and give a larger LED ROI "
        "that holds its whole swing"
    ]


def test_a_sinefit_analysis_is_the_same_whatever_the_callers_jax_precision(scene, render_video):
    import jax

    frames = render_video(scene(latency_s=0.02, duration_s=4.1, fps=120.0))
    with jax.enable_x64(False):
        in_32_bit = analyse(frames, AnalysisOptions(fps=120.0))
        assert not jax.config.jax_enable_x64
    with jax.enable_x64(True):
        in_64_bit = analyse(frames, AnalysisOptions(fps=120.0))
    assert in_32_bit.methods["sinefit"].fit.problem.data.tau.dtype == np.float64
    assert in_32_bit.latency_ms == in_64_bit.latency_ms
    assert in_32_bit.ci95_ms == in_64_bit.ci95_ms
