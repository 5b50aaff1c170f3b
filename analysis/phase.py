"""Steed's phase method: the latency is the phase lag of the sphere's swing behind the LED's.

Each track is reduced to one signal, its displacement along its main axis of motion. The swing
frequency is found from the LED signal: the peak of its Hann-windowed, zero-padded FFT, refined by
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
from analysis.tracking import Track

# Fewest pendulum periods a clip must hold for the frequency and phases to mean anything.
MIN_CYCLES = 2.0
# The FFT for the coarse frequency search is zero-padded to this many times the signal length.
ZERO_PAD = 8
# A track whose displacement along its axis has a smaller standard deviation does not move.
MIN_MOTION_PX = 0.5
# An axis whose x component is smaller than this is taken as vertical (see main_axis).
VERTICAL_X = 0.05
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


def main_axis(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Unit vector along which the points (x, y) spread most (their first principal axis).

    Its sign follows a fixed rule so that two tracks of the same swing share it: the x component
    is positive, or for a vertical axis (|x component| < VERTICAL_X) the y component is.
    """
    points = np.column_stack([x - x.mean(), y - y.mean()])
    _, vectors = np.linalg.eigh(points.T @ points)
    axis = vectors[:, -1]
    flip = axis[1] < 0 if abs(axis[0]) < VERTICAL_X else axis[0] < 0
    return -axis if flip else axis


def axis_signal(track: Track, name: str) -> np.ndarray:
    """A track's displacement along its main axis, mean removed, linearly interpolated where invalid."""
    valid = track.valid
    if np.count_nonzero(valid) < 2:
        raise AnalysisError(f"the {name} was found in fewer than two frames; check its ROI")
    x, y = track.x[valid], track.y[valid]
    axis = main_axis(x, y)
    along = (x - x.mean()) * axis[0] + (y - y.mean()) * axis[1]
    if along.std() < MIN_MOTION_PX:
        raise AnalysisError(
            f"the {name} does not move (it swings less than {MIN_MOTION_PX} px); "
            f"check that the pendulum swings and that the {name} ROI holds the moving {name}"
        )
    signal = np.interp(track.t, track.t[valid], along)
    return signal - signal.mean()


def _centred_times(count: int, fps: float) -> np.ndarray:
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
    times = _centred_times(count, fps)
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
    times = _centred_times(signal.size, fps)
    a, b, _ = _sine_fit(signal, times, np.hanning(signal.size), frequency)
    return math.atan2(-b, a), math.hypot(a, b)


def wrap_phase(angle: float) -> float:
    """The angle wrapped into (-pi, pi]."""
    return math.pi - (math.pi - angle) % (2 * math.pi)


def fft_phase_latency(led: np.ndarray, sphere: np.ndarray, fps: float) -> PhaseEstimate:
    """Latency by Steed's phase method; positive when the sphere lags the LED.

    The latency is only known modulo one period: it is the wrapped phase difference, so values
    near half a period may belong to the other side.
    """
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
