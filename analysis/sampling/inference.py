"""Which display refresh rates, phases, exposures and row slopes a video's sphere timing is
consistent with, and the latency bias each implies.

For a refresh rate f, a row slope m (how the sphere's rows switch and are exposed one after
another, ``analysis.sampling.rows``), an exposure e and a phase phi, every frame's bias follows
(``analysis.sampling.folding``). The sphere's timing misfit, chi^2(f, m, e, phi), scaled by its
residuals' own variance and correlation, is a log likelihood; the weighted mean bias of each
hypothesis is what the latency is off by if it holds.

The candidate rates are the given one or the common ones and those seen in the residuals'
spectrum, each tuned to the clip (``analysis.sampling.rates``); those whose likelihood comes
within CONSISTENT_LOG_LIKELIHOOD of the best remain possible. A display's refreshes and what it
shows are told apart only by the staircase's shape: a renderer that updates the sphere at another
rate than the display's (a 120 Hz tracker held on a 144 Hz display) makes a pattern of its own,
which some other rate may fit better than the display's. So unless the best rate's staircase
explains at least TRUSTED_EXPLAINED of the timing residuals (a display's steps, plainly seen), the
common rates too fast for the camera to see the steps of stay possible, however they fit.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from analysis.sampling.folding import Fit, fit, frame_biases
from analysis.sampling.rates import COMMON_REFRESH_HZ, FINE_EXPOSURE_STEPS, RATE_TOLERANCE, candidate_rates, exposure_grid
from analysis.sampling.residuals import TimingResiduals, inflation
from analysis.sampling.rows import REFINED_GRID, SphereRows

CONSISTENT_LOG_LIKELIHOOD = 6.0
TRUSTED_EXPLAINED = 0.9
# A hypothesis whose bias range spans more than this fraction of what its exposures allow at any
# phase and slope does not place the phase.
UNPLACED = 0.5
# The bias's range holds every hypothesis whose log likelihood comes this close to the best: the 99 %
# profile-likelihood range of one quantity (chi-square of one degree of freedom, 6.63 / 2).
LIKELY_LOG_LIKELIHOOD = 3.3
# The bias's range: all but this much of its posterior either side, and every bias the likelihood
# leaves near the best (LIKELY_LOG_LIKELIHOOD).
BIAS_RANGE = (0.005, 0.995)
# The bias's quantiles are read off a histogram of this many bins over its range.
QUANTILE_BINS = 1 << 16
# Hypotheses this much less likely than the best (a log likelihood 27.6 lower) are dropped.
NEGLIGIBLE_WEIGHT = 1e-12
# Each model is taken to be off by up to this fraction of what it explains, per frame: a display's
# pixels take time to settle, a sphere's light is not a disc's.
MODEL_ERROR = 0.1


@dataclass(frozen=True)
class RefreshHypothesis:
    """A refresh rate (Hz, tuned) the video is consistent with: its best log likelihood, and over
    the row slopes, exposures and phases it allows, each one's latency bias (s) with its posterior
    weight; bounds_s the least and the most bias of every slope, exposure and phase tried."""

    refresh_hz: float
    log_likelihood: float
    biases_s: np.ndarray
    weights: np.ndarray
    bounds_s: tuple[float, float]

    @property
    def mean_s(self) -> float:
        return float(self.weights @ self.biases_s)

    def range_s(self, low: float, high: float) -> tuple[float, float]:
        """The bias's range: its ``low`` and ``high`` quantiles and every bias whose likelihood comes
        within LIKELY_LOG_LIKELIHOOD of the best, where the video places the phase; or every bias
        the exposures allow at any phase and slope where it hardly does (that range spans more than
        UNPLACED of this): the likelihood's fine detail, what pins a phase among equals, is then the
        part of the model least to be trusted. The likelihood's range keeps the answer from resting
        on the prior over the row slope, which no lab states: where the video does not tell the
        slope, a prior spread evenly over slopes up to a display as short as the sphere's travel
        would crowd the posterior into small biases."""
        quantiles = self.quantiles_s(low, high)
        likely = self.biases_s[self.weights >= math.exp(-LIKELY_LOG_LIKELIHOOD) * self.weights.max()]
        spread = (min(quantiles[0], float(likely.min())), max(quantiles[1], float(likely.max())))
        least, most = self.bounds_s
        return (least, most) if spread[1] - spread[0] > UNPLACED * (most - least) else spread

    def quantiles_s(self, low: float, high: float) -> tuple[float, float]:
        """The bias's ``low`` and ``high`` quantiles, each to the outer edge of its bin of a
        QUANTILE_BINS histogram over the biases (a hypothesis may hold a million of them)."""
        edges, cumulative = self._histogram
        first = min(int(np.searchsorted(cumulative, low)), cumulative.size - 1)
        last = min(int(np.searchsorted(cumulative, high)), cumulative.size - 1)
        return float(edges[first]), float(edges[last + 1])

    @functools.cached_property
    def _histogram(self) -> tuple[np.ndarray, np.ndarray]:
        """The edges of QUANTILE_BINS bins over the biases, and the cumulative weight up to each bin's end."""
        least, most = float(self.biases_s.min()), float(self.biases_s.max())
        edges = np.linspace(least, max(most, least + 1e-15), QUANTILE_BINS + 1)
        index = np.clip(((self.biases_s - least) / (edges[-1] - least) * QUANTILE_BINS).astype(np.int64), 0, QUANTILE_BINS - 1)
        return edges, np.cumsum(np.bincount(index, self.weights, QUANTILE_BINS))


def refresh_hypotheses(
    residuals: TimingResiduals,
    fps: float,
    refresh_hz: float | None,
    exposure_s: tuple[float, float],
    bandwidth: int,
    rows: SphereRows | None = None,
) -> list[RefreshHypothesis]:
    """The refresh rates the residuals are consistent with, most likely first: the given one, or
    among the common ones and those seen in the residuals' spectrum (see the module docstring).
    ``exposure_s`` is the range the exposure lies in; ``bandwidth`` (frames) the span over which
    residuals may be correlated; ``rows`` the sphere's rows (None: a point that stays on one row)."""
    exposures = exposure_grid(*exposure_s)
    times = rows.frame_times(residuals.t) if rows is not None else residuals.t
    fits = [fit(residuals, rate, exposures, rows) for rate in candidate_rates(residuals, fps, refresh_hz, exposures, times)]
    scale = min(float(fitted.timing.min()) for fitted in fits) / residuals.r.size
    best = min(fits, key=lambda fitted: float(fitted.timing.min()))
    at = np.unravel_index(int(np.argmin(best.timing)), best.timing.shape)
    left, explained = _leftovers(residuals, best, rows, (int(at[0]), int(at[1]), int(at[2])), float(exposures[at[1]]))
    scale = max(scale * inflation(left, bandwidth), (MODEL_ERROR * explained) ** 2, 1e-300)
    hypotheses = []
    most = max(float(-0.5 * fitted.timing.min() / scale) for fitted in fits)
    unseen = refresh_hz is None and 1.0 - float(best.timing.min()) / float(residuals.r @ residuals.r) < TRUSTED_EXPLAINED
    fine = exposure_grid(*exposure_s, FINE_EXPOSURE_STEPS)
    for fitted in fits:
        top = float(-0.5 * fitted.timing.min() / scale)
        too_fast = unseen and fitted.rate in COMMON_REFRESH_HZ and fitted.rate >= fps * (1 - RATE_TOLERANCE)
        consistent = top >= most - CONSISTENT_LOG_LIKELIHOOD
        if not (consistent or too_fast):
            continue
        # The likelihood may be far narrower in the exposure and the slope than the coarse grid's
        # steps. A rate kept only because the camera cannot see it has nothing to narrow, nor has
        # one whose coarse grid leaves every bias open at more than the given exposure (the
        # refined grid's cost is in its exposures).
        hypothesis = _hypothesis(fitted, fitted, scale, top)
        placed = hypothesis.range_s(*BIAS_RANGE) != hypothesis.bounds_s
        if consistent and (placed or fine.size == exposures.size):
            coarse = np.exp(-0.5 * fitted.timing / scale - top)
            slopes = fitted.slopes
            if rows is not None:
                slopes = rows.refined(fitted.rate, fitted.slopes, coarse.sum(axis=(1, 2)), max(4, REFINED_GRID // fine.size))
            hypothesis = _hypothesis(fitted, fit(residuals, fitted.rate, fine, rows, slopes), scale, top)
        hypotheses.append(hypothesis)
    return sorted(hypotheses, key=lambda h: -h.log_likelihood)


def _hypothesis(coarse: Fit, refined: Fit, scale: float, top: float) -> RefreshHypothesis:
    """The hypothesis of a rate from its fit over the ``refined`` grid (the ``coarse`` one's, or a
    finer one around its likely slopes and exposures), the misfits scaled by ``scale``."""
    log_likelihood = -0.5 * refined.timing / scale
    weights = np.exp(log_likelihood - log_likelihood.max()).ravel()
    kept = weights >= NEGLIGIBLE_WEIGHT
    bounds = (min(float(coarse.mean.min()), float(refined.mean.min())), max(float(coarse.mean.max()), float(refined.mean.max())))
    return RefreshHypothesis(refined.rate, top, refined.mean.ravel()[kept], weights[kept] / weights[kept].sum(), bounds)


def _leftovers(
    residuals: TimingResiduals, fitted: Fit, rows: SphereRows | None, at: tuple[int, int, int], exposure_s: float
) -> tuple[np.ndarray, float]:
    """Per frame, what the hypothesis ``at`` (slope, exposure and phase indices) leaves of the timing
    residuals, and the RMS of what it explains."""
    frame_bias = frame_biases(residuals, fitted, rows, at, exposure_s)
    weights = residuals.v**2
    mean = float(weights @ frame_bias) / max(float(weights.sum()), 1e-300)
    explained = residuals.v * (frame_bias - mean)
    return residuals.r + explained, float(np.sqrt(np.mean(explained**2)))
