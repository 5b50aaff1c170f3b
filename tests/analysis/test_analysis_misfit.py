"""Model-misfit checks after every fit: a clean swing passes them; a latency that changes over the
clip fails them, and the interval widens to the spread of the per-swing latencies, with a warning."""

import dataclasses

import numpy as np

from analysis import estimate, track

# The scene's camera: 240 fps exposing whole frames, filming a 60 Hz display.
KNOWN = {"refresh_hz": 60.0, "exposure_ms": 1e3 / 240.0}


def test_a_clean_swing_passes_every_check(scene, render_video):
    clip = scene(latency_s=0.05, duration_s=6.2)
    result = estimate(track(render_video(clip), fps=clip.fps), **KNOWN)
    assert [check.passed for check in result.checks.checks] == [True] * 4
    assert result.warnings == []
    assert result.ci95_ms[0] < 50.0 < result.ci95_ms[1]


def test_a_latency_that_grows_over_the_clip_fails_the_checks_and_widens_the_interval(scene, render_video):
    # The sphere lags 3 ms more at the end of the clip than at its start.
    clip = scene(latency_s=0.05, duration_s=6.2)
    tracks = track(render_video(clip), fps=clip.fps)
    sphere = tracks.sphere
    t = sphere.t
    lag = 0.003 * (t - t[0]) / (t[-1] - t[0])
    shifted = dataclasses.replace(sphere, x=np.interp(t - lag, t, sphere.x), y=np.interp(t - lag, t, sphere.y))
    result = estimate(dataclasses.replace(tracks, sphere=shifted), **KNOWN)
    failed = {check.name for check in result.checks.failed}
    assert "drift" in failed
    assert any(warning.startswith("the model does not fit the swing") for warning in result.warnings)
    statistical = result.methods["sinefit"].details["statistical_ci95_ms"]
    assert result.ci95_ms[1] - result.ci95_ms[0] > statistical[1] - statistical[0]
    # The mean lag, 1.5 ms more than at the start, lies inside.
    assert result.ci95_ms[0] < 51.5 < result.ci95_ms[1]
