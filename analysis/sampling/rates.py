"""Which refresh rates a video's sphere timing may come from: the given one tuned, or the common ones
and those a line in the timing's spectrum points to.

A display's and a camera's clocks run off their nominal rates by up to RATE_TOLERANCE, which over
a clip of seconds shifts the phase by much of a refresh, so each nominal rate is first tuned
within that tolerance to where the folded residuals line up best (the sum of squares the per-bin
means explain), when they line up better than chance. Without a rate from the user the candidates
are the common refresh rates and the rates whose refreshes alias onto a line in the residuals'
spectrum.
"""

from __future__ import annotations

import math

import numpy as np

from analysis.sampling.folding import Folding, bias_spectrum, fit_one
from analysis.sampling.residuals import TimingResiduals

COMMON_REFRESH_HZ = (50.0, 59.94, 60.0, 72.0, 75.0, 85.0, 90.0, 100.0, 119.88, 120.0, 144.0, 165.0, 240.0)
# Refresh rates a display may have, for rates found from a line in the residuals' spectrum.
RATE_RANGE_HZ = (23.0, 500.0)
RATE_TOLERANCE = 1e-3
FOLD_BINS = 64
# A rate is tuned in steps that move the phase by this fraction of a refresh over the clip, after
# a coarser search in steps COARSE_STEPS times larger, with phases folded into TUNING_BINS bins.
TUNING_STEP_REFRESHES = 0.02
COARSE_STEPS = 5
TUNING_BINS = 128
# Folded residuals line up better than chance when they explain this many standard deviations
# more than noise would.
FOLD_SIGMAS = 6.0
# Exposures tried for every rate, then for the rates that remain possible.
EXPOSURE_STEPS = 8
FINE_EXPOSURE_STEPS = 48
# A spectral line: this many times the median power, above LINE_MIN_HZ (slower lines are the
# swing's own harmonics).
LINE_POWER = 25.0
LINE_MIN_HZ = 8.0
SPECTRUM_PAD = 4


def tuned_rate(residuals: TimingResiduals, nominal_hz: float, exposures_s: np.ndarray, noise: float, times: np.ndarray) -> float:
    """The rate within RATE_TOLERANCE of nominal whose hypotheses fit the residuals' timing best
    (searched coarsely, then finely around the best), or the nominal rate when the residuals folded
    at it show no pattern at all (nothing to tune by)."""
    chance = noise * (FOLD_BINS + FOLD_SIGMAS * math.sqrt(2 * FOLD_BINS))
    if Folding(residuals, nominal_hz, FOLD_BINS, times).explained() <= chance:
        return nominal_hz
    duration = float(residuals.t[-1] - residuals.t[0]) if residuals.t.size > 1 else 0.0
    half = RATE_TOLERANCE * nominal_hz
    fine = TUNING_STEP_REFRESHES / max(duration, 1e-9)
    if half < fine:
        return nominal_hz

    # Within the tolerance the model hardly changes: only the folding moves.
    spectrum = bias_spectrum(nominal_hz, exposures_s, TUNING_BINS)

    def misfit(rate: float) -> float:
        return float(fit_one(residuals, spectrum, Folding(residuals, rate, TUNING_BINS, times))[0].min())

    coarse = min(half, COARSE_STEPS * fine)
    rates = nominal_hz + coarse * np.arange(-math.floor(half / coarse), math.floor(half / coarse) + 1)
    best = float(rates[int(np.argmin([misfit(rate) for rate in rates]))])
    rates = best + fine * np.arange(-COARSE_STEPS, COARSE_STEPS + 1)
    rates = rates[np.abs(rates - nominal_hz) <= half]
    return float(rates[int(np.argmin([misfit(rate) for rate in rates]))])


def spectral_rates(residuals: TimingResiduals, fps: float) -> list[float]:
    """Refresh rates (within RATE_RANGE_HZ) whose refreshes alias onto the strongest line of the
    residuals' timing spectrum, if it stands out."""
    series = np.zeros(int(residuals.index[-1]) + 1)
    series[residuals.index] = residuals.v * residuals.r
    size = 1 << math.ceil(math.log2(SPECTRUM_PAD * series.size))
    power = np.abs(np.fft.rfft(series - series.mean(), size)) ** 2
    frequencies = np.fft.rfftfreq(size, 1.0 / fps)
    usable = frequencies >= LINE_MIN_HZ
    if not np.any(usable):
        return []
    peak = int(np.argmax(np.where(usable, power, 0.0)))
    if power[peak] < LINE_POWER * float(np.median(power[usable])):
        return []
    line = float(frequencies[peak])
    low, high = RATE_RANGE_HZ
    rates = []
    for multiple in range(int(high / fps) + 2):
        for rate in (multiple * fps - line, multiple * fps + line):
            if low <= rate <= high:
                rates.append(rate)
    return rates


def exposure_grid(low_s: float, high_s: float, steps: int = EXPOSURE_STEPS) -> np.ndarray:
    if high_s - low_s <= 1e-9 * high_s:
        return np.array([high_s])
    return np.linspace(max(low_s, 0.02 * high_s), high_s, steps)


def candidate_rates(
    residuals: TimingResiduals, fps: float, refresh_hz: float | None, exposures: np.ndarray, times: np.ndarray
) -> list[float]:
    """The rates to fit, each tuned (see the module docstring); the frames at ``times`` (their frame times)."""
    noise = float(residuals.r @ residuals.r) / residuals.r.size
    coarse = exposures[:: max(1, exposures.size // 3)]
    if refresh_hz is not None:
        return [tuned_rate(residuals, refresh_hz, coarse, noise, times)]
    # A line in the spectrum places the refreshes to within a fraction of a spectral bin: only its
    # aliases need tuning; without one, the common rates may be near-locked and drifting.
    seen = spectral_rates(residuals, fps)
    rates = {tuned_rate(residuals, rate, coarse, noise, times) for rate in seen or COMMON_REFRESH_HZ}
    return sorted(rates | (set(COMMON_REFRESH_HZ) if seen else set()))
