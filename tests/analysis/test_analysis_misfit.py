"""Model-misfit checks after every fit: a clean swing passes them; a latency that changes over the
clip fails them, and the interval widens to the spread of the per-swing latencies, with a warning."""

import dataclasses

import numpy as np

from analysis import AnalysisOptions, estimate, track
from analysis.misfit import check_fit
from analysis.sampling.residuals import TimingResiduals
from analysis.swing import measure_swing
from analysis.blobs import Track

# The scene's camera: 240 fps exposing whole frames with a global shutter, filming a 60 Hz display.
KNOWN = {"display_hz": 60.0, "exposure_ms": 1e3 / 240.0, "readout_ms": 0.0}


def checked(clip, render_video, sphere_x=None, lag_s=None):
    """The estimate of ``clip`` with its sphere track changed: its x mapped by ``sphere_x(x, t)``,
    or delayed by a further ``lag_s(t)``; and the names of the checks that failed."""
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps))
    sphere = tracks.sphere
    t = sphere.t
    if sphere_x is not None:
        sphere = dataclasses.replace(sphere, x=sphere_x(sphere.x, t))
    if lag_s is not None:
        lag = lag_s(t)
        sphere = dataclasses.replace(sphere, x=np.interp(t - lag, t, sphere.x), y=np.interp(t - lag, t, sphere.y))
    result = estimate(dataclasses.replace(tracks, sphere=sphere), AnalysisOptions(**KNOWN))
    return result, {check.name for check in result.checks.failed}


def test_a_clean_swing_passes_every_check(scene, render_video):
    clip = scene(latency_s=0.05, duration_s=6.2)
    result = estimate(track(render_video(clip), AnalysisOptions(fps=clip.fps)), AnalysisOptions(**KNOWN))
    assert [check.passed for check in result.checks.checks] == [True] * 4
    assert result.warnings == []
    assert result.ci95_ms[0] < 50.0 < result.ci95_ms[1]


def test_a_latency_that_grows_over_the_clip_fails_the_checks_and_widens_the_interval(scene, render_video):
    # The sphere lags 3 ms more at the end of the clip than at its start.
    clip = scene(latency_s=0.05, duration_s=6.2)
    tracks = track(render_video(clip), AnalysisOptions(fps=clip.fps))
    sphere = tracks.sphere
    t = sphere.t
    lag = 0.003 * (t - t[0]) / (t[-1] - t[0])
    shifted = dataclasses.replace(sphere, x=np.interp(t - lag, t, sphere.x), y=np.interp(t - lag, t, sphere.y))
    result = estimate(dataclasses.replace(tracks, sphere=shifted), AnalysisOptions(**KNOWN))
    failed = {check.name for check in result.checks.failed}
    assert "drift" in failed
    assert any(warning.startswith("the model does not fit the swing") for warning in result.warnings)
    statistical = result.methods["sinefit"].details["statistical_ci95_ms"]
    assert result.ci95_ms[1] - result.ci95_ms[0] > statistical[1] - statistical[0]
    # The mean lag, 1.5 ms more than at the start, lies inside.
    assert result.ci95_ms[0] < 51.5 < result.ci95_ms[1]


def test_a_latency_that_alternates_from_swing_to_swing_fails_consistency_not_drift(scene, render_video):
    # The sphere lags 1.5 ms more on every other swing: no trend, but swings that disagree.
    clip = scene(latency_s=0.05, duration_s=6.2)
    alternation = lambda t: 0.0015 * np.sign(np.sin(np.pi * t / clip.period_s + 0.3))  # noqa: E731
    result, failed = checked(clip, render_video, lag_s=alternation)
    assert "per-swing consistency" in failed and "drift" not in failed
    assert any(warning.startswith("the model does not fit the swing (per-swing consistency") for warning in result.warnings)
    statistical = result.methods["sinefit"].details["statistical_ci95_ms"]
    assert result.ci95_ms[1] - result.ci95_ms[0] > 1.3 * (statistical[1] - statistical[0])
    t = result.sphere_track.t
    mean_lag_ms = 50.0 + 1e3 * float(np.mean(alternation(t)))
    assert result.ci95_ms[0] < mean_lag_ms < result.ci95_ms[1]


def test_a_sphere_swing_that_shrinks_against_the_leds_leaves_the_swing_frequency_in_the_residuals(scene, render_video):
    # A display whose image of the swing shrinks by 10 % over the clip while the LED's does not:
    # the residuals keep a line at the swing frequency, which no constant latency explains.
    clip = scene(latency_s=0.05, duration_s=6.2)

    def shrinking(x: np.ndarray, t: np.ndarray) -> np.ndarray:
        return np.nanmean(x) + (x - np.nanmean(x)) * (1 - 0.1 * (t - t[0]) / np.ptp(t))

    result, failed = checked(clip, render_video, sphere_x=shrinking)
    assert failed == {"residual harmonics"}
    assert any("residual harmonics: the residuals keep the swing frequency itself" in w for w in result.warnings)
    assert result.ci95_ms[0] < 50.0 < result.ci95_ms[1]


def _swinging(periods: int, fps: float = 60.0) -> tuple[Track, Track]:
    """An LED and a sphere 50 ms behind it, swinging for ``periods`` 1 s periods, as tracks."""
    t = np.arange(round(periods * fps)) / fps
    ones, none = np.ones(t.size), np.zeros(t.size, dtype=bool)

    def blob(delay: float) -> Track:
        x = 80.0 + 25.0 * np.exp(-0.02 * t) * np.sin(2 * np.pi * (t - delay))
        return Track(t=t, x=x, y=np.full(t.size, 50.0), valid=~none, peak=ones, clipped=none)

    return blob(0.0), blob(0.05)


def _residual_correlation(swing, r: np.ndarray) -> bool:
    index = np.arange(r.size)
    residuals = TimingResiduals(index / swing.fps, r, np.ones(r.size), index, 1.0 / swing.fps)
    report = check_fit(swing, None, residuals, half_width_s=1e-3)
    (correlation,) = [check for check in report.checks if check.name == "residual correlation"]
    return correlation.passed


def test_residuals_that_wander_over_many_periods_fail_the_correlation_check():
    # 60 periods: a random walk in the residuals (a display image that drifts) fails; independent
    # residuals, or residuals correlated within a period only, pass.
    swing = measure_swing(*_swinging(60), {})
    rng = np.random.default_rng(7)
    size = swing.signals.t.size
    assert not _residual_correlation(swing, 0.2 * np.cumsum(rng.standard_normal(size)))
    assert _residual_correlation(swing, rng.standard_normal(size))
    within_period = np.convolve(rng.standard_normal(size + 29), np.ones(30) / 30, mode="valid")
    assert _residual_correlation(swing, within_period)
