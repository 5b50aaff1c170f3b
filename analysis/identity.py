"""Which of two blobs is the LED and which the rendered sphere, by physical evidence.

Brightness decides nothing: a dim LED or a bright display is common. What differs physically:

- refresh steps: the display shows the sphere in steps, one pose a refresh, so a camera faster
  than the display sees it stand still and jump; the LED moves continuously. Against a smooth
  curve through each track (a local cubic over about SMOOTHING_PERIODS of a swing), the sphere's
  residuals, as timing (over its speed), repeat with the refreshes: a line in their spectrum.
  Noise does not make a line, however it grows with speed (a blurred LED is measured less
  precisely), and what a blob's crossing of compression blocks makes is a line of a few
  hundredths of a millisecond, where a display's steps make a millisecond or more. A blob's step
  score is how far its strongest line stands above LINE_POWER times the spectrum's median, in
  decades, where that line is at least STEP_MIN_S of timing; the blob with the higher score is the
  sphere.
- saturation: the LED is a point of light bright enough to saturate its core in most frames; a
  display's sphere rarely reaches the sensor's top level.
- size: the LED is point-like; the sphere is a drawn disc, usually larger in the image.
- side: the rig puts the LED left of the display (``rig simulate`` and the layout docs/filming.md advises).

Each is a log-odds that the first (left) blob is the LED; their sum must reach DECISION_MARGIN
either way, or no decision is made and the caller asks the user for the regions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.blobs import Track
from analysis.phase import estimate_frequency
from analysis.sampling.exposure import SATURATED_LEVEL
from analysis.signals import swing_signals

DECISION_MARGIN = 3.0
SMOOTHING_PERIODS = 0.08
LINE_POWER = 25.0
LINE_MIN_HZ = 8.0
STEP_MIN_S = 0.2e-3
STEP_WEIGHT = 3.0
STEP_LIMIT = 6.0
# Most frames saturated against few.
SATURATED_MOST, SATURATED_FEW = 0.5, 0.1
SATURATION_WEIGHT = 3.0
# A size ratio of e counts this much, up to SIZE_LIMIT.
SIZE_WEIGHT = 1.5
SIZE_LIMIT = 1.5
SIDE_WEIGHT = 1.0


@dataclass(frozen=True)
class Identity:
    """The decision: whether the first blob is the LED, the total log-odds, and each evidence's."""

    first_is_led: bool | None
    margin: float
    evidence: dict[str, float]

    def rule(self) -> str:
        """How the LED was told from the sphere, for the result's ``led_rule``."""
        used = ", ".join(f"{name} {value:+.1f}" for name, value in self.evidence.items() if value)
        return f"auto: by physical evidence (log-odds the left blob is the LED: {used or 'none'}; total {self.margin:+.1f})"


def _smooth(values: np.ndarray, width: int) -> tuple[np.ndarray, np.ndarray]:
    """(value, slope per sample) of a local cubic least-squares fit over ``width`` samples (odd)."""
    half = width // 2
    offsets = np.arange(-half, half + 1, dtype=np.float64)
    basis = np.vander(offsets, 4, increasing=True)
    solver = np.linalg.pinv(basis)
    padded = np.pad(values, half, mode="reflect", reflect_type="odd")
    value = np.convolve(padded, solver[0][::-1], mode="valid")
    slope = np.convolve(padded, solver[1][::-1], mode="valid")
    return value, slope


def step_score(signal: np.ndarray, frame_interval: float, period_s: float) -> float:
    """How strongly a blob moves in steps: the decades by which the strongest line (above
    LINE_MIN_HZ) of its residuals' timing spectrum exceeds LINE_POWER times the median (0 for
    continuous motion)."""
    valid = np.isfinite(signal)
    if np.count_nonzero(valid) < 32:
        return 0.0
    index = np.arange(signal.size)
    filled = np.interp(index, index[valid], signal[valid])
    width = max(5, 2 * round(SMOOTHING_PERIODS * period_s / frame_interval / 2) + 1)
    if width >= signal.size:
        return 0.0
    smooth, slope = _smooth(filled, width)
    # Per frame, the residual as a time (s), weighted by speed: a frame at rest says nothing.
    timing = np.where(valid, (filled - smooth) * slope, 0.0) * frame_interval / max(float(np.mean(slope[valid] ** 2)), 1e-300)
    size = 1 << math.ceil(math.log2(2 * timing.size))
    spectrum = np.abs(np.fft.rfft(timing - timing.mean(), size))
    usable = np.fft.rfftfreq(size, frame_interval) >= LINE_MIN_HZ
    if np.count_nonzero(usable) < 8:
        return 0.0
    peak = float(spectrum[usable].max())
    if 2 * peak / np.count_nonzero(valid) < STEP_MIN_S:
        return 0.0
    ratio = peak**2 / max(float(np.median(spectrum[usable] ** 2)), 1e-300)
    return max(0.0, math.log10(ratio / LINE_POWER))


def _saturated(track: Track) -> float:
    if track.level is None:
        return 0.0
    return float(np.mean(track.level[track.valid] >= SATURATED_LEVEL))


def _size(track: Track) -> float | None:
    """The blob's typical radius (px): the square root of its smaller principal second moment,
    median over frames (the larger includes motion blur)."""
    if track.spread is None:
        return None
    sxx, syy, sxy = track.spread[track.valid].T
    smaller = (sxx + syy) / 2 - np.sqrt(((sxx - syy) / 2) ** 2 + sxy**2)
    smaller = smaller[np.isfinite(smaller) & (smaller > 0)]
    return math.sqrt(float(np.median(smaller))) if smaller.size else None


def decide(first: Track, second: Track, signals: tuple[np.ndarray, np.ndarray], frame_interval: float, period_s: float) -> Identity:
    """Whether ``first`` (the left blob) is the LED, from the evidence in the module docstring;
    ``signals`` are both blobs' displacements along their axes (NaN where missing)."""
    evidence = {}
    scores = [step_score(signal, frame_interval, period_s) for signal in signals]
    evidence["refresh steps"] = float(np.clip(STEP_WEIGHT * (scores[1] - scores[0]), -STEP_LIMIT, STEP_LIMIT))
    saturated = (_saturated(first), _saturated(second))
    if saturated[0] >= SATURATED_MOST and saturated[1] <= SATURATED_FEW:
        evidence["saturation"] = SATURATION_WEIGHT
    elif saturated[1] >= SATURATED_MOST and saturated[0] <= SATURATED_FEW:
        evidence["saturation"] = -SATURATION_WEIGHT
    else:
        evidence["saturation"] = 0.0
    sizes = (_size(first), _size(second))
    evidence["size"] = (
        float(np.clip(SIZE_WEIGHT * math.log(sizes[1] / sizes[0]), -SIZE_LIMIT, SIZE_LIMIT))
        if sizes[0] and sizes[1]
        else 0.0
    )
    evidence["side"] = SIDE_WEIGHT
    margin = sum(evidence.values())
    decided = None if abs(margin) < DECISION_MARGIN else margin > 0
    return Identity(decided, margin, evidence)


def identify(first: Track, second: Track) -> Identity:
    """Whether ``first`` (the left blob) is the LED, from both whole tracks (see ``decide``)."""
    signals = swing_signals(first, second)
    frequency = estimate_frequency(signals.uniform()[1], 1.0 / signals.frame_interval)
    return decide(first, second, (signals.led, signals.sphere), signals.frame_interval, 1.0 / frequency)
