"""The swing one period at a time: phases and amplitudes per window, and latency over time.

The clip is cut into consecutive windows one swing period long. In each, each signal's valid
samples are fitted by c0 + c1 s + sum over k = 1, 2, 3 of exp(-k gamma s) [a_k cos(k omega s) +
b_k sin(k omega s)], s = t - t_mid, at the clip's swing frequency omega and damping gamma (the
harmonics and the envelope keep a wide or decaying swing from leaking into the drift term by an
amount that depends on each signal's phase), giving its phase psi = atan2(-b, a) (the signal is
A cos(omega (t - t_mid) + psi)) and amplitude A at the window's middle t_mid. The phase difference
gives a latency per window: the "latency over time" a lab looks at to see whether latency varies,
with its mean and standard deviation (the sigma of the seed papers' latency tables).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.signals import SwingSignals

# A window is used for a signal only if its valid samples cover this fraction of it...
MIN_COVERAGE = 0.75
# ...and number at least this many.
MIN_SAMPLES = 12
# Parameters of a window's fit: offset, drift, and cos and sin of the swing and its 2nd and 3rd harmonics.
WINDOW_PARAMETERS = 8


@dataclass(frozen=True)
class WindowPhases:
    """Per window (one swing period each): middle time, and each signal's phase and amplitude.

    Phases are unwrapped along the windows; NaN where a signal had too few valid samples.
    led_noise and sphere_noise are the RMS residuals (px) of the per-window fits, over all windows.
    """

    t: np.ndarray
    led_phase: np.ndarray
    sphere_phase: np.ndarray
    led_amplitude: np.ndarray
    sphere_amplitude: np.ndarray
    omega: float
    led_noise: float
    sphere_noise: float

    @property
    def both(self) -> np.ndarray:
        """Windows where both signals have a phase."""
        return np.isfinite(self.led_phase) & np.isfinite(self.sphere_phase)


@dataclass(frozen=True)
class WindowedLatency:
    """Latency per window (s), unwrapped to lie within half a period of a reference, and its statistics."""

    t: np.ndarray
    latency_s: np.ndarray
    mean_s: float
    sd_s: float
    count: int
    window_s: float

    def to_dict(self) -> dict[str, object]:
        return {
            "window_s": self.window_s,
            "count": self.count,
            "mean_ms": self.mean_s * 1e3,
            "sd_ms": self.sd_s * 1e3,
            "t_s": [round(float(t), 6) for t in self.t],
            "latency_ms": [round(float(v) * 1e3, 6) for v in self.latency_s],
        }


def _window_fit(
    t: np.ndarray, values: np.ndarray, omega: float, period: float, damping: float
) -> tuple[float, float, float, int]:
    """(phase, amplitude, residual sum of squares, samples) of one signal in one window; NaN if too sparse."""
    valid = np.isfinite(values)
    if np.count_nonzero(valid) < MIN_SAMPLES:
        return math.nan, math.nan, 0.0, 0
    times, data = t[valid], values[valid]
    if times[-1] - times[0] < MIN_COVERAGE * period:
        return math.nan, math.nan, 0.0, 0
    angle = omega * times
    envelope = np.exp(-damping * times)
    columns = [np.ones_like(times), times]
    for order in (1, 2, 3):
        columns += [envelope**order * np.cos(order * angle), envelope**order * np.sin(order * angle)]
    basis = np.column_stack(columns)
    coefficients, *_ = np.linalg.lstsq(basis, data, rcond=None)
    residual = data - basis @ coefficients
    a, b = coefficients[2], coefficients[3]
    return math.atan2(-b, a), math.hypot(a, b), float(residual @ residual), int(times.size)


def window_phases(signals: SwingSignals, frequency_hz: float, damping: float = 0.0) -> WindowPhases:
    """Phases and amplitudes (those of the fundamental) of both signals in consecutive one-period
    windows of frames, each signal fitted at its own times; ``damping`` (1/s, see damping_rate)
    shapes the swing inside each window."""
    period = 1.0 / frequency_hz
    omega = 2 * math.pi * frequency_hz
    start = signals.t[0]
    count = int((signals.t[-1] - start) // period)
    edges = np.searchsorted(signals.t, start + period * np.arange(count + 1))
    middles = start + period * (np.arange(count) + 0.5)
    rows = {"led": [], "sphere": []}
    squares = {"led": [0.0, 0], "sphere": [0.0, 0]}
    for index in range(count):
        sl = slice(edges[index], edges[index + 1])
        for name, times, values in (("led", signals.t[sl], signals.led[sl]), ("sphere", signals.sphere_t[sl], signals.sphere[sl])):
            phase, amplitude, rss, used = _window_fit(times - middles[index], values, omega, period, damping)
            rows[name].append((phase, amplitude))
            squares[name][0] += rss
            squares[name][1] += max(used - WINDOW_PARAMETERS, 0)
    led = np.array(rows["led"], dtype=np.float64).reshape(-1, 2)
    sphere = np.array(rows["sphere"], dtype=np.float64).reshape(-1, 2)
    return WindowPhases(
        t=middles,
        led_phase=_unwrapped(led[:, 0]),
        sphere_phase=_unwrapped(sphere[:, 0]),
        led_amplitude=led[:, 1],
        sphere_amplitude=sphere[:, 1],
        omega=omega,
        led_noise=math.sqrt(squares["led"][0] / max(squares["led"][1], 1)),
        sphere_noise=math.sqrt(squares["sphere"][0] / max(squares["sphere"][1], 1)),
    )


def _unwrapped(phases: np.ndarray) -> np.ndarray:
    out = phases.copy()
    finite = np.isfinite(phases)
    out[finite] = np.unwrap(phases[finite])
    return out


def damping_rate(windows: WindowPhases) -> float:
    """The LED's amplitude decay rate gamma (1/s): the slope of log amplitude against time, negated.

    Zero when fewer than two windows have an amplitude.
    """
    valid = np.isfinite(windows.led_amplitude) & (windows.led_amplitude > 0)
    if np.count_nonzero(valid) < 2:
        return 0.0
    slope = np.polyfit(windows.t[valid], np.log(windows.led_amplitude[valid]), 1)[0]
    return float(-slope)


def gain_ratio(windows: WindowPhases) -> float:
    """The sphere's amplitude over the LED's, the median over windows."""
    both = windows.both & (windows.led_amplitude > 0)
    if not np.any(both):
        return 1.0
    return float(np.median(windows.sphere_amplitude[both] / windows.led_amplitude[both]))


def windowed_latency(windows: WindowPhases, reference_s: float) -> WindowedLatency | None:
    """Latency per window, each taken within half a period of ``reference_s``; None without windows."""
    both = windows.both
    if not np.any(both):
        return None
    period = 2 * math.pi / windows.omega
    raw = (windows.led_phase[both] - windows.sphere_phase[both]) / windows.omega
    latency = raw - period * np.round((raw - reference_s) / period)
    return WindowedLatency(
        t=windows.t[both],
        latency_s=latency,
        mean_s=float(latency.mean()),
        sd_s=float(latency.std(ddof=1)) if latency.size > 1 else 0.0,
        count=int(latency.size),
        window_s=period,
    )
