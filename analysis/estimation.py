"""The second part of an analysis: both tracks in, the latency out (``estimate`` -> ``LatencyResult``).

The free swing is measured once (``analysis.swing``); its phase lag, known modulo one period, and
the swing's one-off events decide the whole number of periods (``analysis.cycles``); then each
requested estimator (``analysis.estimators``) runs on the same context, each taking that same
whole number of periods.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from analysis.cycles import DEFAULT_LATENCY_RANGE_S, resolve_cycles
from analysis.errors import AnalysisError
from analysis.estimators.contract import EstimationContext
from analysis.estimators.registry import ALL, DEFAULT_METHOD, estimators_for
from analysis.phase import fft_phase_latency
from analysis.result import LatencyResult
from analysis.swing import measure_swing
from analysis.timing import implausible_period_warning
from analysis.tracking import Track
from analysis.tracks import Tracks
from analysis.windows import windowed_latency


def latency_range_s(latency_range_ms: Sequence[float]) -> tuple[float, float]:
    """The plausible latency range in s; AnalysisError unless it is two finite numbers, low < high (ms)."""
    low, high = (float(v) for v in latency_range_ms)
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise AnalysisError(f"latency range {list(latency_range_ms)!r} ms must be two finite numbers, low < high")
    return low / 1e3, high / 1e3


def estimate(
    tracks: Tracks,
    method: str = DEFAULT_METHOD,
    *,
    latency_range_ms: Sequence[float] = tuple(v * 1e3 for v in DEFAULT_LATENCY_RANGE_S),
    seed: int = 0,
    reference_departures: Callable[[Track], Mapping[str, float]] | None = None,
) -> LatencyResult:
    """Measure by how much the sphere lags the LED in tracks from ``analysis.tracks.track``.

    ``method`` is a registered estimator's name (``analysis.estimators.registry.methods()``: fft,
    xcorr, sinefit, bayes, and any registered since) or "all" (every one, the default method's
    result reported). Latencies are looked for in ``latency_range_ms``. ``seed`` seeds the bayes
    sampler. ``reference_departures(led_track)`` names times (s, on the video's clock) at which
    other instruments saw the pendulum depart from rest, in the sense of ``analysis.onset`` (e.g. a
    rig board's encoder, its clock aligned by the LED's blink code, which it reads from the LED
    track); with the sphere's departure each gives a lag that fixes the whole number of periods.
    """
    estimators = estimators_for(method)
    range_s = latency_range_s(latency_range_ms)
    started = time.perf_counter()
    warnings = list(tracks.warnings)
    references = reference_departures(tracks.led) if reference_departures is not None else {}
    swing = measure_swing(tracks.led, tracks.sphere, references)
    period_warning = implausible_period_warning(swing.period_s, tracks.times)
    if period_warning:
        warnings.append(period_warning)
    _, led, sphere = swing.uniform
    wrapped = fft_phase_latency(led, sphere, swing.fps, swing.frequency_hz).latency_s
    cycles = resolve_cycles(wrapped, swing.period_s, swing.windows, swing.damping, range_s, swing.events_s)
    if cycles.warning:
        warnings.append(cycles.warning)
    context = EstimationContext(swing, cycles, seed, warnings)
    results = {estimator.name: estimator.estimate(context) for estimator in estimators}
    primary = results[DEFAULT_METHOD if method == ALL else method]
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
        led_track=tracks.led,
        sphere_track=tracks.sphere,
    )
