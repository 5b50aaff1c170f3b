"""The second part of an analysis: both tracks in, the latency out (``estimate`` -> ``LatencyResult``).

First each blob's samples are dated by the rows they come from where the camera's readout is
given, or the readout is bounded by the frame rate (``analysis.readout``). The free swing is then
measured once (``analysis.swing``); its phase lag, known modulo one period, and the swing's
one-off events decide the whole number of periods (``analysis.cycles``); then each requested
estimator (``analysis.estimators``) runs on the same context, each taking that same whole number
of periods. Every estimate is then checked for model misfit (``analysis.misfit``, which widens a
failing estimate's interval), for the camera's sampling of the display (``analysis.sampling``,
which corrects the bias where the video identifies it and otherwise widens the interval by it),
and, for a readout only bounded, widened by the bias the blobs' rows allow; each adds a warning
when it changed something.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from analysis.cycles import resolve_cycles
from analysis.estimators.contract import EstimationContext
from analysis.estimators.registry import ALL, DEFAULT_METHOD, estimators_for
from analysis.misfit import MisfitReport, check_fit
from analysis.options import AnalysisOptions
from analysis.phase import fft_phase_latency
from analysis.result import LatencyResult, MethodResult
from analysis.sampling import SamplingBias, measure_sampling
from analysis.sampling.residuals import timing_residuals
from analysis.readout import RollingShutter, rolling_shutter
from analysis.swing import during, measure_swing
from analysis.timing import implausible_period_warning
from analysis.blobs import Track
from analysis.tracks import Tracks
from analysis.windows import windowed_latency


def estimate(
    tracks: Tracks,
    options: AnalysisOptions = AnalysisOptions(),
    *,
    reference_departures: Callable[[Track], Mapping[str, float]] | None = None,
) -> LatencyResult:
    """Measure by how much the sphere lags the LED in tracks from ``analysis.tracks.track``.

    Of the ``options`` (``analysis.options.AnalysisOptions``), ``method`` is a registered
    estimator's name (``analysis.estimators.registry.methods()``: fft, xcorr, sinefit, bayes, and
    any registered since) or "all" (every one, the default method's result reported); latencies are
    looked for in ``latency_range_ms``; ``seed`` seeds the bayes sampler; ``display_hz`` (the
    display's refresh rate) and ``exposure_ms`` (the camera's exposure) are what the user knows of
    them, and without them the video is searched for both (``analysis.sampling``); ``readout_ms``
    is the camera's readout, the time its rolling shutter takes from the frame's top row to its
    bottom one (0 for a global shutter), and without it the interval allows for any readout up to
    the frame interval (``analysis.readout``).
    ``reference_departures(led_track)`` names times (s, on the video's clock) at which other
    instruments saw the pendulum depart from rest, in the sense of ``analysis.onset`` (e.g. a rig
    board's encoder, its clock aligned by the LED's blink code, which it reads from the LED track);
    with the sphere's departure each gives a lag that fixes the whole number of periods.
    """
    method = options.method
    estimators = estimators_for(method)
    range_s = options.latency_range_s
    started = time.perf_counter()
    warnings = list(tracks.warnings)
    shutter = rolling_shutter(tracks.led, tracks.sphere, tracks.frame_size[1], options.readout_ms)
    led_track, sphere_track = shutter.dated(tracks.led), shutter.dated(tracks.sphere)
    references = reference_departures(led_track) if reference_departures is not None else {}
    swing = measure_swing(led_track, sphere_track, references)
    period_warning = implausible_period_warning(swing.period_s, tracks.times)
    if period_warning:
        warnings.append(period_warning)
    _, led, sphere = swing.uniform
    wrapped = fft_phase_latency(led, sphere, swing.fps, swing.frequency_hz).latency_s
    cycles = resolve_cycles(wrapped, swing.period_s, swing.windows, swing.damping, range_s, swing.events_s)
    if cycles.warning:
        warnings.append(cycles.warning)
    context = EstimationContext(swing, cycles, options.seed, warnings)
    results = {estimator.name: estimator.estimate(context) for estimator in estimators}
    primary_name = DEFAULT_METHOD if method == ALL else method
    measured = results[primary_name]
    residuals = timing_residuals(swing.signals, measured.latency_ms / 1e3, during(sphere_track, swing.span_s, led_track.t))
    half_width_s = (measured.ci95_ms[1] - measured.ci95_ms[0]) / 2e3 if measured.ci95_ms is not None else 0.0
    checks = check_fit(swing, windowed_latency(swing.windows, measured.latency_ms / 1e3), residuals, half_width_s)
    sampling = (
        measure_sampling(
            residuals,
            led_track,
            swing.period_s,
            options.display_hz,
            None if options.exposure_ms is None else options.exposure_ms / 1e3,
            (shutter.row_time_s, shutter.row_time_range_s),
        )
        if residuals is not None
        else None
    )
    results = {name: _adjusted(result, checks, sampling) for name, result in results.items()}
    sampled = results[primary_name]
    shutter_warning = shutter.warning(_interval_s(sampled))
    results = {name: _widened_for_shutter(result, shutter) for name, result in results.items()}
    primary = results[primary_name]
    for warning in (checks.warning(), _sampling_warning(sampling, measured, sampled, checks), shutter_warning):
        if warning:
            warnings.append(warning)
    both = tracks.led.valid & tracks.sphere.valid
    diagnostics: dict[str, Any] = {
        **tracks.diagnostics,
        "latency_range_ms": [range_s[0] * 1e3, range_s[1] * 1e3],
        "swinging_s": [float(swing.span_s[0]), float(swing.span_s[1])],
        "damping_per_s": swing.damping,
        "track_seconds": tracks.seconds,
        "estimate_seconds": time.perf_counter() - started,
    }
    return LatencyResult(
        latency_ms=primary.latency_ms,
        ci95_ms=primary.ci95_ms,
        method=primary.method,
        model=primary.model,
        period_s=swing.period_s,
        fps=tracks.times.fps,
        frames=int(tracks.times.t.size),
        frames_used=int(np.count_nonzero(both)),
        ambiguous=cycles.ambiguous,
        warnings=warnings,
        led_roi=tracks.led_roi,
        sphere_roi=tracks.sphere_roi,
        roi_source=tracks.roi_source,
        led_rule=tracks.led_rule,
        methods=results,
        cycles=cycles,
        windowed=windowed_latency(swing.windows, primary.latency_ms / 1e3),
        diagnostics=diagnostics,
        sampling=sampling,
        checks=checks,
        shutter=shutter,
        led_track=led_track,
        sphere_track=sphere_track,
    )


def _interval_s(result: MethodResult) -> tuple[float, float] | None:
    return None if result.ci95_ms is None else (result.ci95_ms[0] / 1e3, result.ci95_ms[1] / 1e3)


def _widened_for_shutter(result: MethodResult, shutter: RollingShutter) -> MethodResult:
    """An estimator's result with its interval widened by the bias a readout only bounded allows."""
    interval = shutter.widen(result.latency_ms / 1e3, _interval_s(result))
    if interval is None:
        return result
    return dataclasses.replace(result, ci95_ms=(interval[0] * 1e3, interval[1] * 1e3))


def _adjusted(result: MethodResult, checks: MisfitReport, sampling: SamplingBias | None) -> MethodResult:
    """An estimator's result with its interval widened by a failed check, then corrected and
    widened for the camera's sampling of the display."""
    latency_s = result.latency_ms / 1e3
    ci_s = None if result.ci95_ms is None else (result.ci95_ms[0] / 1e3, result.ci95_ms[1] / 1e3)
    widened = checks.widen(latency_s, ci_s)
    corrected, interval = sampling.apply(latency_s, widened) if sampling is not None else (latency_s, widened)
    details = {
        **result.details,
        "measured_ms": result.latency_ms,
        "statistical_ci95_ms": result.ci95_ms and list(result.ci95_ms),
        "sampling_correction_ms": (latency_s - corrected) * 1e3,
    }
    return dataclasses.replace(
        result,
        latency_ms=corrected * 1e3,
        ci95_ms=None if interval is None else (interval[0] * 1e3, interval[1] * 1e3),
        details=details,
    )


def _sampling_warning(
    sampling: SamplingBias | None, measured: MethodResult, adjusted: MethodResult, checks: MisfitReport
) -> str | None:
    """The sampling's warning about the primary estimate, ``measured`` before and ``adjusted``
    after the checks and the sampling changed it."""
    if sampling is None:
        return None
    ci_s = None if measured.ci95_ms is None else (measured.ci95_ms[0] / 1e3, measured.ci95_ms[1] / 1e3)
    final = None if adjusted.ci95_ms is None else (adjusted.ci95_ms[0] / 1e3, adjusted.ci95_ms[1] / 1e3)
    return sampling.warning(checks.widen(measured.latency_ms / 1e3, ci_s), final)
