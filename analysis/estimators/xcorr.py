"""Cross-correlation (``xcorr``): the lag at which the sphere's track best matches the LED's.

Both signals are on a uniform time grid (gaps interpolated). Their cross-correlation, computed by
FFT over all lags, peaks once per swing period; the peak taken is the one within half a period of
the reference latency (which fixes the whole number of periods, see ``analysis.cycles``). Around
it the correlation is recomputed as a Pearson coefficient over the overlapping samples (so the
shrinking overlap at larger lags does not tilt the peak), and the peak's position between samples
comes from the cosine through the three highest points: near its peak the correlation of two
swings is a cosine of the lag, which a parabola would fit with a bias.
"""

from __future__ import annotations

import math
import time

import numpy as np

from analysis.errors import AnalysisError
from analysis.estimators.contract import EstimationContext
from analysis.result import MethodResult


def pearson_at_lag(led: np.ndarray, sphere: np.ndarray, lag: int) -> float:
    """Correlation of led[i] with sphere[i + lag] over the samples where both exist."""
    if lag >= 0:
        a, b = led[: led.size - lag], sphere[lag:]
    else:
        a, b = led[-lag:], sphere[: sphere.size + lag]
    a = a - a.mean()
    b = b - b.mean()
    return float(a @ b / math.sqrt((a @ a) * (b @ b)))


def cosine_peak(before: float, at: float, after: float) -> float:
    """Offset (in samples, within +-1) of the peak of A cos(theta (d - offset)) through three points."""
    ratio = (before + after) / (2 * at)
    if at <= 0 or not -1 < ratio < 1:
        return 0.0
    theta = math.acos(ratio)
    return math.atan((after - before) / (2 * at * math.sin(theta))) / theta


def xcorr_latency(led: np.ndarray, sphere: np.ndarray, fps: float, period_s: float, reference_s: float) -> float:
    """Latency (s) of the sphere behind the LED: the correlation peak nearest ``reference_s``."""
    count = led.size
    size = 1 << math.ceil(math.log2(2 * count))
    spectrum = np.conj(np.fft.rfft(led - led.mean(), size)) * np.fft.rfft(sphere - sphere.mean(), size)
    correlation = np.fft.irfft(spectrum, size)
    lags = np.arange(-(count - 1), count)
    values = np.concatenate([correlation[size - count + 1 :], correlation[:count]])
    near = np.abs(lags / fps - reference_s) <= period_s / 2
    # Keep at least a period's worth of overlap.
    near &= np.abs(lags) <= count - period_s * fps
    if not np.any(near):
        raise AnalysisError(
            f"the clip is too short to cross-correlate at a lag near {reference_s * 1e3:.0f} ms; "
            "record a longer video"
        )
    best = int(lags[near][np.argmax(values[near])])
    before, at, after = (pearson_at_lag(led, sphere, best + d) for d in (-1, 0, 1))
    return (best + cosine_peak(before, at, after)) / fps


class CrossCorrelationEstimator:
    """The lag of the cross-correlation peak nearest the chosen latency."""

    name = "xcorr"
    gives_interval = False

    def estimate(self, context: EstimationContext) -> MethodResult:
        started = time.perf_counter()
        swing = context.swing
        _, led, sphere = swing.uniform
        latency = xcorr_latency(led, sphere, swing.fps, swing.period_s, context.cycles.reference_s)
        return MethodResult(self.name, latency * 1e3, None, "sine", time.perf_counter() - started, {})
