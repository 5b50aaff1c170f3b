"""The analysis in parts: ``track`` gives the tracks and how they were found, ``estimate`` the latency,
and ``analyse`` is the one after the other."""

import numpy as np

from analysis import AnalysisOptions, Tracks, analyse, estimate, track


def test_analyse_is_track_then_estimate(scene, render_video):
    clip = scene(latency_s=0.03, duration_s=3.0, fps=120.0)
    frames = render_video(clip).copy()
    frames[10, :, 80:] = 21
    tracks = track(frames, AnalysisOptions(fps=clip.fps))
    assert isinstance(tracks, Tracks)
    assert tracks.roi_source == "auto" and tracks.led_rule.startswith("auto: by physical evidence")
    assert tracks.warnings == (
        "the sphere was missing in 1 frames (0.3%), of them 1 dark (off or hidden); those frames were left out\n"
        "to avoid it: keep the sphere lit and in view while filming",
    )
    assert np.array_equal(tracks.stamps, np.arange(clip.frame_count) / clip.fps)
    assert tracks.led.t is tracks.times.t and tracks.diagnostics["time_source"] == tracks.times.source
    known = {"display_hz": clip.display_hz, "exposure_ms": 1e3 / clip.fps, "readout_ms": 0.0}
    whole = analyse(frames, AnalysisOptions(fps=clip.fps, method="fft", **known))
    parts = estimate(tracks, AnalysisOptions(method="fft", **known))
    assert parts.latency_ms == whole.latency_ms
    assert parts.warnings == whole.warnings == list(tracks.warnings)
    assert (parts.led_roi, parts.sphere_roi) == (whole.led_roi, whole.sphere_roi) == (tracks.led_roi, tracks.sphere_roi)
    assert np.array_equal(parts.sphere_track.x, whole.sphere_track.x, equal_nan=True)


def test_one_set_of_tracks_serves_every_estimate(scene, render_video):
    clip = scene(latency_s=0.03, duration_s=3.0, fps=120.0)
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps))
    fft = estimate(tracks, AnalysisOptions(method="fft"))
    xcorr = estimate(tracks, AnalysisOptions(method="xcorr", latency_range_ms=(-100.0, 300.0)))
    assert fft.led_track is xcorr.led_track is tracks.led
    assert abs(fft.latency_ms - xcorr.latency_ms) < 0.5
    assert xcorr.diagnostics["latency_range_ms"] == [-100.0, 300.0]
    assert tracks.warnings == ()
