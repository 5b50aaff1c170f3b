"""Steed's phase method (``fft``): the latency is the phase lag of the sphere's swing behind the LED's.

Both signals are on a uniform time grid (gaps interpolated). The swing frequency is found from the LED signal: the peak of its Hann-windowed, zero-padded FFT, refined by
a golden-section search. The phase of each signal at that frequency comes from the windowed DTFT,
sum_n w[n] x[n] exp(-2 pi i f t[n]), with the 3x3 Gram correction that removes what the signal's
negative-frequency image and its mean leak into that sum. The correction turns the DTFT into the
window-weighted least-squares fit of c + a cos(2 pi f t) + b sin(2 pi f t), so the phase is exact
for a pure sine whatever the number of periods in the clip; plain FFT-bin phases are biased when
that number is not a whole one. Both phases are taken at the same frequency and relative to the
same time, so what damping and the window do to one signal they do to the other and the
difference stays unbiased.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from analysis.errors import AnalysisError

# Fewest pendulum periods a clip must hold for the frequency and phases to mean anything.
MIN_CYCLES = 2.0
# The FFT for the coarse frequency search is zero-padded to this many times the signal length.
ZERO_PAD = 8
# Relative tolerance of the refined frequency (a maximum is located to about sqrt(machine epsilon)).
FREQUENCY_TOLERANCE = 1e-9


@dataclass(frozen=True)
class PhaseEstimate:
    """Result of the phase method. Phases are in radians at the middle of the clip."""

    latency_s: float
    frequency_hz: float
    cycles: float
    led_phase: float
    sphere_phase: float
    led_amplitude: float
    sphere_amplitude: float


def centred_times(count: int, fps: float) -> np.ndarray:
    """Times of ``count`` uniform samples at ``fps``, measured from the middle of the clip."""
    return (np.arange(count, dtype=np.float64) - (count - 1) / 2) / fps


def _sine_fit(
    signal: np.ndarray, times: np.ndarray, window: np.ndarray, frequency: float
) -> tuple[float, float, float]:
    """(cos coefficient, sin coefficient, fitted power) of the window-weighted fit of c + a cos + b sin."""
    angle = 2 * math.pi * frequency * times
    basis = np.column_stack([np.ones_like(times), np.cos(angle), np.sin(angle)])
    weighted = basis * window[:, None]
    gram = basis.T @ weighted
    projection = weighted.T @ signal
    coefficients = np.linalg.solve(gram, projection)
    return float(coefficients[1]), float(coefficients[2]), float(projection @ coefficients)


def _golden_section_max(fun: Callable[[float], float], low: float, high: float, tolerance: float) -> float:
    """Argument of the maximum of a unimodal function on [low, high]."""
    ratio = (math.sqrt(5) - 1) / 2
    inner_low, inner_high = high - ratio * (high - low), low + ratio * (high - low)
    value_low, value_high = fun(inner_low), fun(inner_high)
    while high - low > tolerance:
        if value_low >= value_high:
            high, inner_high, value_high = inner_high, inner_low, value_low
            inner_low = high - ratio * (high - low)
            value_low = fun(inner_low)
        else:
            low, inner_low, value_low = inner_low, inner_high, value_high
            inner_high = low + ratio * (high - low)
            value_high = fun(inner_high)
    return (low + high) / 2


def estimate_frequency(signal: np.ndarray, fps: float) -> float:
    """Swing frequency in Hz: windowed zero-padded FFT peak, refined by maximising the fitted power.

    The search skips frequencies below one period per clip. Raises AnalysisError when the clip
    holds fewer than MIN_CYCLES periods at the frequency found.
    """
    count = signal.size
    window = np.hanning(count)
    size = 1 << math.ceil(math.log2(ZERO_PAD * count))
    spectrum = np.abs(np.fft.rfft(window * signal, size))
    bin_hz = fps / count
    first = math.ceil(bin_hz * size / fps)
    peak = first + int(np.argmax(spectrum[first:]))
    coarse = peak * fps / size
    times = centred_times(count, fps)
    frequency = _golden_section_max(
        lambda f: _sine_fit(signal, times, window, f)[2],
        max(coarse - bin_hz, bin_hz / 2),
        coarse + bin_hz,
        FREQUENCY_TOLERANCE * coarse,
    )
    cycles = frequency * count / fps
    if cycles < MIN_CYCLES:
        raise AnalysisError(
            f"the video holds only {cycles:.1f} pendulum periods ({count / fps:.2f} s at "
            f"{frequency:.3g} Hz); record at least {MIN_CYCLES:g} periods, ideally 10 or more"
        )
    return frequency


def sine_phase(signal: np.ndarray, fps: float, frequency: float) -> tuple[float, float]:
    """(phase in radians, amplitude) of the signal's component at ``frequency``, at mid-clip.

    The phase follows the DTFT sign convention: A cos(2 pi f t + phase).
    """
    times = centred_times(signal.size, fps)
    a, b, _ = _sine_fit(signal, times, np.hanning(signal.size), frequency)
    return math.atan2(-b, a), math.hypot(a, b)


def wrap_phase(angle: float) -> float:
    """The angle wrapped into (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2 * math.pi)


def fft_phase_latency(
    led: np.ndarray, sphere: np.ndarray, fps: float, frequency: float | None = None
) -> PhaseEstimate:
    """Latency by Steed's phase method; positive when the sphere lags the LED.

    ``frequency`` is the LED's swing frequency if already known (else it is estimated). The
    latency is only known modulo one period: it is the wrapped phase difference (see
    ``analysis.cycles`` for the whole number of periods).
    """
    if frequency is None:
        frequency = estimate_frequency(led, fps)
    led_phase, led_amplitude = sine_phase(led, fps, frequency)
    sphere_phase, sphere_amplitude = sine_phase(sphere, fps, frequency)
    lag = wrap_phase(led_phase - sphere_phase)
    return PhaseEstimate(
        latency_s=lag / (2 * math.pi * frequency),
        frequency_hz=frequency,
        cycles=frequency * led.size / fps,
        led_phase=led_phase,
        sphere_phase=sphere_phase,
        led_amplitude=led_amplitude,
        sphere_amplitude=sphere_amplitude,
    )
