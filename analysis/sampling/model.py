"""How a camera's exposure samples a sample-and-hold display: the timing bias of the sphere.

A display holds each refresh's image until the next refresh reaches the sphere's row, so the
sphere it emits is a staircase: at time t it shows the content of the last switch, which is
``age(t)`` old, 0 <= age < T (T = 1 / refresh rate). The true latency (what an ideal analyser
measures) is the delay of that staircase behind the LED, the content's delay plus T / 2. A camera
frame averages the scene over its exposure [t, t + E]: the LED's position over it, and the
staircase's. To first order in the swing's speed the frame sees the sphere as late as the
staircase's mean age over the exposure, so it reads the latency too long by

    b = mean over the exposure of (age - T / 2) = T g(s, e),
    g(s, e) = (F(s + e) - F(s)) / e,  F(a) = (frac(a)^2 - frac(a)) / 2,

where s is the exposure's start as a fraction of a refresh after the sphere's row switched and
e = E / T the exposure in refreshes. g rises with slope 1 while the exposure holds no switch and
falls back while it does; its mean over s is zero, and it is zero for every s when e is a whole
number (the exposure covers whole refreshes). An analysis measures the latency as long as the
frames' biases' mean, weighted by how much each frame tells about timing (the sphere's speed
squared). Where camera and display rates are incommensurate the frames' phases s fill the refresh
and the mean is zero; where they are commensurate, p/q in lowest terms, the frames visit p phases
only, 1 / p of a refresh apart, and the mean depends on where the switch falls among them: when
no exposure holds it, anywhere in a gap of (T / p - E) between exposures, the bias lies anywhere
in +-(T / p - E) / 2 (phase-locked, p = 1: up to half a refresh). ``analysis.sampling.inference``
works out which phases a video is consistent with.

The sphere is not a point: its rows switch one after another as the display's scan-out reaches
them (``analysis.sampling.rows``), so a frame's bias is g averaged over its rows' phases.
"""

from __future__ import annotations

import numpy as np


def _antiderivative(a: np.ndarray) -> np.ndarray:
    """F(a) = (frac(a)^2 - frac(a)) / 2: periodic, continuous, F' = frac(a) - 1/2."""
    f = a - np.floor(a)
    return 0.5 * (f * f - f)


def exposure_bias(s: np.ndarray | float, e: np.ndarray | float) -> np.ndarray:
    """g(s, e): a frame's latency bias in refreshes, for an exposure of ``e`` refreshes (> 0)
    starting ``s`` refreshes after the sphere's row switched (broadcast)."""
    s, e = np.asarray(s, dtype=np.float64), np.asarray(e, dtype=np.float64)
    return (_antiderivative(s + e) - _antiderivative(s)) / e


def frame_phases(times: np.ndarray, refresh_hz: float, phase: np.ndarray | float) -> np.ndarray:
    """Each frame's exposure start as a fraction of a refresh after the sphere's row switched:
    frac(refresh_hz t + phase), ``phase`` placing the switches against the frame times (broadcast
    over a trailing axis of phases when given an array)."""
    phase = np.asarray(phase, dtype=np.float64)
    values = refresh_hz * np.asarray(times)[..., None] + phase if phase.ndim else refresh_hz * np.asarray(times) + phase
    return values - np.floor(values)


def bias_range_s(refresh_hz: float, camera_fps: float, exposure_s: float) -> float:
    """The half-width (s) of the range the bias may take, over the display's unknown phase, for a
    camera whose rate is exactly commensurate with the display's, p/q in lowest terms (up to 1000),
    or 0 where the exposure holds a switch whatever the phase. Incommensurate rates: 0 (the
    phases fill the refresh given long enough a film; see ``film_bias_s``)."""
    ratio = commensurate(camera_fps / refresh_hz)
    if ratio is None:
        return 0.0
    p, _ = ratio
    period = 1.0 / refresh_hz
    e = exposure_s * refresh_hz
    if np.isclose(e, round(e), atol=1e-9) and round(e) >= 1:
        return 0.0
    return max(period / p - exposure_s, 0.0) / 2 if e < 1 else _worst_over_phase(refresh_hz, camera_fps, exposure_s, p)


def _worst_over_phase(refresh_hz: float, camera_fps: float, exposure_s: float, p: int) -> float:
    """Half the spread of the p-phase mean bias over the display's phase, by brute force."""
    phases = np.linspace(0.0, 1.0, 720, endpoint=False)
    frames = np.arange(p) / camera_fps
    means = exposure_bias(frame_phases(frames, refresh_hz, phases), exposure_s * refresh_hz).mean(axis=0)
    return float(np.ptp(means)) / 2 / refresh_hz


def commensurate(value: float, largest: int = 1000) -> tuple[int, int] | None:
    """(p, q) with value = p / q in lowest terms and q <= largest (within a part in 10^9), or None:
    a camera at ``value`` times the display's rate visits p phases of its refresh."""
    for q in range(1, largest + 1):
        p = round(value * q)
        if p >= 1 and abs(p / q - value) < 1e-9 * value:
            return p, q
    return None
