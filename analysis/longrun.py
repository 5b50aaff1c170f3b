"""The variance of a sum of correlated terms (Newey-West), shared by the fit's interval and the
sampling analysis."""

from __future__ import annotations

import math

import numpy as np


def long_run_variance(series: np.ndarray, bandwidth: int) -> float:
    """Newey-West variance of a sum of a correlated series: Bartlett-weighted autocovariances."""
    count = series.size
    bandwidth = min(bandwidth, count - 1)
    size = 1 << math.ceil(math.log2(2 * count))
    spectrum = np.fft.rfft(series, size)
    autocovariance = np.fft.irfft(np.abs(spectrum) ** 2, size)[: bandwidth + 1]
    lags = np.arange(bandwidth + 1)
    weights = 1.0 - lags / (bandwidth + 1)
    return float(autocovariance[0] + 2 * np.sum(weights[1:] * autocovariance[1:]))
