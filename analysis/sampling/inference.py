"""Which display refresh rates, phases and exposures a video's sphere timing is consistent with,
and the latency bias each implies.

For a refresh rate f, a phase phi (where the sphere's row switches against the frame times) and
an exposure e (in refreshes), every frame's bias is b_n = g(frac(f t_n + phi), e) / f
(``analysis.sampling.model``), and the sphere's residuals should read r_n = -v_n (b_n - mean b)
(``analysis.sampling.residuals``); where the sphere's moments were measured, its elongation along
its motion should read c + (v_n / f)^2 V(frac(f t_n + phi), e), c its own (fitted). Each misfit,
chi^2(f, phi, e), scaled by its residuals' own variance and correlation, is a log likelihood, and
the two add; the weighted mean bias of each hypothesis is what the latency is off by if it holds.

Frames are folded by their phase frac(f t_n) into PHASE_BINS bins: every phi is then a circular
shift, and chi^2 over all phases takes three FFTs per (f, e). A display's and a camera's clocks run
off their nominal rates by up to RATE_TOLERANCE, which over a clip of seconds shifts the phase by
much of a refresh, so each nominal rate is first tuned within that tolerance to where the folded
residuals line up best (the sum of squares the per-bin means explain), when they line up better
than chance. Without a rate from the user the candidates are the common refresh rates and the
rates whose refreshes alias onto a line in the residuals' spectrum; those whose likelihood comes
within CONSISTENT_LOG_LIKELIHOOD of the best remain possible. A display's refreshes and what it
shows are told apart only by the staircase's shape: a renderer that updates the sphere at another
rate than the display's (a 120 Hz tracker held on a 144 Hz display) makes a pattern of its own,
which some other rate may fit better than the display's. So unless the best rate's staircase
explains at least TRUSTED_EXPLAINED of the timing residuals (a display's steps, plainly seen), the
common rates too fast for the camera to see the steps of stay possible, however they fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.sampling.model import exposure_bias, exposure_spread
from analysis.sampling.residuals import TimingResiduals, inflation

COMMON_REFRESH_HZ = (50.0, 59.94, 60.0, 72.0, 75.0, 85.0, 90.0, 100.0, 119.88, 120.0, 144.0, 165.0, 240.0)
# Refresh rates a display may have, for rates found from a line in the residuals' spectrum.
RATE_RANGE_HZ = (23.0, 500.0)
RATE_TOLERANCE = 1e-3
PHASE_BINS = 512
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
# The elongation counts where at least this many frames measured it.
SHAPE_MIN_FRAMES = 32
CONSISTENT_LOG_LIKELIHOOD = 6.0
TRUSTED_EXPLAINED = 0.9
# A hypothesis whose bias quantiles span more than this fraction of what its exposures allow at any
# phase does not place the phase.
UNPLACED = 0.5
# Each model is taken to be off by up to this fraction of what it explains, per frame: the sphere
# spans rows that switch at different times, a display's pixels take time to settle.
MODEL_ERROR = 0.1
# The elongation is trusted to this fraction of the largest a double image gives (two equal images a
# refresh's travel apart, at the swing's typical speed).
SHAPE_RESOLUTION = 0.2
# A spectral line: this many times the median power, above LINE_MIN_HZ (slower lines are the
# swing's own harmonics).
LINE_POWER = 25.0
LINE_MIN_HZ = 8.0
SPECTRUM_PAD = 4


@dataclass(frozen=True)
class RefreshHypothesis:
    """A refresh rate (Hz, tuned) the video is consistent with: its best log likelihood, and over
    the phases and exposures it allows, each one's latency bias (s) with its posterior weight."""

    refresh_hz: float
    log_likelihood: float
    biases_s: np.ndarray
    weights: np.ndarray

    @property
    def mean_s(self) -> float:
        return float(self.weights @ self.biases_s)

    def range_s(self, low: float, high: float) -> tuple[float, float]:
        """The bias's range: its ``low`` and ``high`` quantiles where the video places the phase, or
        every bias the exposures allow at any phase where it hardly does (the quantiles span more
        than UNPLACED of that): the likelihood's fine detail, what pins a phase among equals, is
        then the part of the model least to be trusted (the sphere's rows do not all switch at
        once, and switch at different times as it moves up and down the display)."""
        quantiles = self.quantiles_s(low, high)
        least, most = float(self.biases_s.min()), float(self.biases_s.max())
        return (least, most) if quantiles[1] - quantiles[0] > UNPLACED * (most - least) else quantiles

    def quantiles_s(self, low: float, high: float) -> tuple[float, float]:
        order = np.argsort(self.biases_s)
        cumulative = np.cumsum(self.weights[order])
        values = self.biases_s[order]
        return float(values[np.searchsorted(cumulative, low)]), float(values[min(np.searchsorted(cumulative, high), values.size - 1)])


class _Folding:
    """The residuals' sums per phase bin at a refresh rate: W = sum v^2 and X = sum v r for the
    timing; for the elongation D (frames where it was measured), sum v^2, sum v^4, sum D v^2 and
    its totals."""

    def __init__(self, residuals: TimingResiduals, refresh_hz: float, bins: int, shape: bool = True) -> None:
        phase = refresh_hz * residuals.t
        index = ((phase - np.floor(phase)) * bins).astype(np.int64) % bins
        v2 = residuals.v**2
        self.index = index
        self.w = np.bincount(index, v2, bins)
        self.x = np.bincount(index, residuals.v * residuals.r, bins)
        self.shape: tuple[np.ndarray, np.ndarray, np.ndarray, float, float, int] | None = None
        if shape and residuals.elongation is not None:
            measured = np.isfinite(residuals.elongation)
            if np.count_nonzero(measured) >= SHAPE_MIN_FRAMES:
                where, d, q = index[measured], residuals.elongation[measured], v2[measured]
                sums = (np.bincount(where, q, bins), np.bincount(where, q * q, bins), np.bincount(where, d * q, bins))
                self.shape = (*sums, float(d.sum()), float(d @ d), int(d.size))

    def explained(self) -> float:
        """The sum of squares a free timing offset per bin explains."""
        used = self.w > 0
        return float(np.sum(self.x[used] ** 2 / self.w[used]))


@dataclass(frozen=True)
class _Model:
    """A rate's model per phase bin and exposure: the bias (s) and its square, the elongation factor
    V / f^2 and its square, as spectra along the bins (for circular correlation)."""

    rate: float
    bins: int
    spectra: tuple[np.ndarray, ...]


def _model(rate: float, exposures_s: np.ndarray, bins: int = PHASE_BINS, shape: bool = True) -> _Model:
    centres = (np.arange(bins) + 0.5) / bins
    exposures = exposures_s[:, None] * rate
    biases = exposure_bias(centres[None, :], exposures) / rate
    tables = [biases, biases**2]
    if shape:
        spread = exposure_spread(centres[None, :], exposures) / rate**2
        tables += [spread, spread**2]
    return _Model(rate, bins, tuple(np.fft.rfft(table, axis=1) for table in tables))


@dataclass(frozen=True)
class _Fit:
    """One rate's misfits over (exposures, phases): the timing's, the elongation's (None where not
    measured), and each hypothesis's weighted mean bias (s)."""

    rate: float
    folding: _Folding
    timing: np.ndarray
    shape: np.ndarray | None
    mean: np.ndarray


def _fit(residuals: TimingResiduals, model: _Model, rate: float | None = None) -> _Fit:
    """The misfits of ``model`` for every exposure and phase j / bins, the frames folded at ``rate``
    (the model's own by default): each phase a circular shift of the per-bin model, so a few FFTs."""
    rate = model.rate if rate is None else rate
    folding = _Folding(residuals, rate, model.bins, shape=len(model.spectra) > 2)

    def correlate(values: np.ndarray, spectrum: np.ndarray) -> np.ndarray:
        return np.fft.irfft(np.conj(np.fft.rfft(values))[None, :] * spectrum, model.bins, axis=1)

    bias, bias_square = model.spectra[:2]
    total_w, total_x = folding.w.sum(), folding.x.sum()
    mean = correlate(folding.w, bias) / max(total_w, 1e-300)
    squares = float(residuals.r @ residuals.r)
    timing = squares + 2 * correlate(folding.x, bias) - 2 * mean * total_x + correlate(folding.w, bias_square) - mean**2 * total_w
    shape_chi2 = None
    if folding.shape is not None:
        spread, spread_square = model.spectra[2:]
        q, q2, dq, total_d, total_d2, count = folding.shape
        cross, model_sum = correlate(dq, spread), correlate(q, spread)
        shape_chi2 = total_d2 - 2 * cross + correlate(q2, spread_square) - (total_d - model_sum) ** 2 / count
    return _Fit(rate, folding, timing, shape_chi2, mean)


def _tuned_rate(residuals: TimingResiduals, nominal_hz: float, exposures_s: np.ndarray, noise: float) -> float:
    """The rate within RATE_TOLERANCE of nominal whose hypotheses fit the residuals' timing best
    (searched coarsely, then finely around the best), or the nominal rate when the residuals folded
    at it show no pattern at all (nothing to tune by)."""
    chance = noise * (FOLD_BINS + FOLD_SIGMAS * math.sqrt(2 * FOLD_BINS))
    if _Folding(residuals, nominal_hz, FOLD_BINS).explained() <= chance:
        return nominal_hz
    duration = float(residuals.t[-1] - residuals.t[0]) if residuals.t.size > 1 else 0.0
    half = RATE_TOLERANCE * nominal_hz
    fine = TUNING_STEP_REFRESHES / max(duration, 1e-9)
    if half < fine:
        return nominal_hz

    # Within the tolerance the model hardly changes: only the folding moves.
    model = _model(nominal_hz, exposures_s, TUNING_BINS, shape=False)

    def misfit(rate: float) -> float:
        return float(_fit(residuals, model, rate).timing.min())

    coarse = min(half, COARSE_STEPS * fine)
    rates = nominal_hz + coarse * np.arange(-math.floor(half / coarse), math.floor(half / coarse) + 1)
    best = float(rates[int(np.argmin([misfit(rate) for rate in rates]))])
    rates = best + fine * np.arange(-COARSE_STEPS, COARSE_STEPS + 1)
    rates = rates[np.abs(rates - nominal_hz) <= half]
    return float(rates[int(np.argmin([misfit(rate) for rate in rates]))])


def _spectral_rates(residuals: TimingResiduals, fps: float) -> list[float]:
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


def _exposure_grid(low_s: float, high_s: float, steps: int = EXPOSURE_STEPS) -> np.ndarray:
    if high_s - low_s <= 1e-9 * high_s:
        return np.array([high_s])
    return np.linspace(max(low_s, 0.02 * high_s), high_s, steps)


def _candidate_rates(residuals: TimingResiduals, fps: float, refresh_hz: float | None, exposures: np.ndarray) -> list[float]:
    noise = float(residuals.r @ residuals.r) / residuals.r.size
    coarse = exposures[:: max(1, exposures.size // 3)]
    if refresh_hz is not None:
        return [_tuned_rate(residuals, refresh_hz, coarse, noise)]
    # A line in the spectrum places the refreshes to within a fraction of a spectral bin: only its
    # aliases need tuning; without one, the common rates may be near-locked and drifting.
    seen = _spectral_rates(residuals, fps)
    rates = {_tuned_rate(residuals, rate, coarse, noise) for rate in seen or COMMON_REFRESH_HZ}
    return sorted(rates | (set(COMMON_REFRESH_HZ) if seen else set()))


def refresh_hypotheses(
    residuals: TimingResiduals, fps: float, refresh_hz: float | None, exposure_s: tuple[float, float], bandwidth: int
) -> list[RefreshHypothesis]:
    """The refresh rates the residuals are consistent with, most likely first: the given one, or
    among the common ones and those seen in the residuals' spectrum (see the module docstring).
    ``exposure_s`` is the range the exposure lies in; ``bandwidth`` (frames) the span over which
    residuals may be correlated."""
    exposures = _exposure_grid(*exposure_s)
    fits = [_fit(residuals, _model(rate, exposures)) for rate in _candidate_rates(residuals, fps, refresh_hz, exposures)]
    with_shape = all(fit.shape is not None for fit in fits)
    timing_scale = min(float(fit.timing.min()) for fit in fits) / residuals.r.size
    shape_scale = min(float(fit.shape.min()) for fit in fits) / fits[0].folding.shape[5] if with_shape else 1.0

    def misfit(fit: _Fit, timing: float, shape: float) -> np.ndarray:
        return fit.timing / timing + (fit.shape / shape if with_shape else 0.0)

    best = min(fits, key=lambda fit: float(misfit(fit, timing_scale, shape_scale).min()))
    exposure_index, phase_index = np.unravel_index(int(np.argmin(misfit(best, timing_scale, shape_scale))), best.timing.shape)
    left = _leftovers(residuals, best, float(exposures[exposure_index]), int(phase_index))
    timing_scale = max(timing_scale * inflation(left[0], bandwidth), (MODEL_ERROR * left[2]) ** 2, 1e-300)
    if with_shape:
        # Only a clear double image counts: the sphere's rows switch one after another, so a switch
        # near an exposure's edge doubles some rows of it and not others.
        straddle = SHAPE_RESOLUTION * 0.25 * float(np.sqrt(np.mean(residuals.v**4))) / best.rate**2
        shape_scale = max(shape_scale * inflation(left[1], bandwidth), (MODEL_ERROR * left[3]) ** 2, straddle**2, 1e-300)
    hypotheses = []
    most = max(float(-0.5 * misfit(fit, timing_scale, shape_scale).min()) for fit in fits)
    unseen = refresh_hz is None and 1.0 - float(best.timing.min()) / float(residuals.r @ residuals.r) < TRUSTED_EXPLAINED
    fine = _exposure_grid(*exposure_s, FINE_EXPOSURE_STEPS)
    for fit in fits:
        top = float(-0.5 * misfit(fit, timing_scale, shape_scale).min())
        too_fast = unseen and fit.rate in COMMON_REFRESH_HZ and fit.rate >= fps * (1 - RATE_TOLERANCE)
        if top < most - CONSISTENT_LOG_LIKELIHOOD and not too_fast:
            continue
        # The likelihood may be far narrower in the exposure than the coarse grid's steps.
        refined = _fit(residuals, _model(fit.rate, fine)) if fine.size > exposures.size else fit
        log_likelihood = -0.5 * misfit(refined, timing_scale, shape_scale)
        weights = np.exp(log_likelihood - log_likelihood.max()).ravel()
        hypotheses.append(RefreshHypothesis(fit.rate, top, refined.mean.ravel(), weights / weights.sum()))
    return sorted(hypotheses, key=lambda h: -h.log_likelihood)


def _leftovers(
    residuals: TimingResiduals, fit: _Fit, exposure_s: float, phase_index: int
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Per frame, what a hypothesis leaves of the timing residuals and of the measured elongations,
    and the RMS of what it explains of each."""
    rate = fit.rate
    centres = (np.arange(PHASE_BINS) + 0.5) / PHASE_BINS
    phase = (fit.folding.index + phase_index) % PHASE_BINS
    frame_bias = (exposure_bias(centres, exposure_s * rate) / rate)[phase]
    weights = residuals.v**2
    mean = float(weights @ frame_bias) / max(float(weights.sum()), 1e-300)
    explained = residuals.v * (frame_bias - mean)
    timing = residuals.r + explained
    timing_rms = float(np.sqrt(np.mean(explained**2)))
    if residuals.elongation is None:
        return timing, np.zeros(1), timing_rms, 0.0
    measured = np.isfinite(residuals.elongation)
    model = (weights * (exposure_spread(centres, exposure_s * rate) / rate**2)[phase])[measured]
    shape = residuals.elongation[measured] - model
    return timing, shape - shape.mean(), timing_rms, float(np.sqrt(np.mean((model - model.mean()) ** 2)))
