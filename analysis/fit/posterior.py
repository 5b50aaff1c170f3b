"""The posterior of the latency (``bayes``): emcee over the same model ``sinefit`` chose.

The sampled parameters are the model's free non-linear ones (frequency, damping, chirp, lag, gain,
in the scaled units of ``analysis.fit.model``) and the log noise scale of each signal; the linear
coefficients are integrated out analytically (flat priors), so the walkers move in at most seven
dimensions. Priors are flat over a box BOX_WIDTH least-squares standard errors wide around the
fit (and within half a period for the lag: the whole number of periods was chosen before, see
``analysis.cycles``), and over LOG_NOISE_RANGE for the log noise scales.

Walkers start from the fit's Laplace approximation (its covariance, inflated as below) and move
by differential-evolution proposals, which suit a near-Gaussian posterior.

The likelihood is divided by the variance inflation the sandwich estimator found for the fit
(a coarsened likelihood: correlated residuals carry as much information as fewer independent
ones), times (critical / 1.96)^2 with the fit's fixed-b critical value, so the posterior's width
accounts for correlated residuals, and for how few periods pin down their variance, as the fit's
interval does.
The reported latency is the posterior median with the central 95 % credible interval; the JSON
holds the integrated autocorrelation time and the mean acceptance fraction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import emcee
import jax
import jax.numpy as jnp
import numpy as np

from analysis.fit import model
from analysis.fit.least_squares import SineFit
from analysis.fit.marginal import in_float64, log_marginal

WALKERS = 32
BURN_IN = 150
STEPS = 600
BOX_WIDTH = 50.0
LOG_NOISE_RANGE = (-5.0, 5.0)
# Latency samples kept for plots.
KEPT_SAMPLES = 4000
# Chains longer than this many autocorrelation times count as converged (emcee suggests 50 for a
# precise autocorrelation time; the quantiles need fewer).
CONVERGED_TIMES = 25
NORMAL_95 = 1.959963984540054


@dataclass(frozen=True)
class Posterior:
    """The latency's posterior: median and central 95 % interval (s), and the sampler's diagnostics."""

    median_s: float
    ci95_s: tuple[float, float]
    samples_s: np.ndarray
    autocorrelation_steps: float
    acceptance: float
    walkers: int
    steps: int
    burn_in: int
    inflation: float

    @property
    def converged(self) -> bool:
        return self.steps > CONVERGED_TIMES * self.autocorrelation_steps

    def details(self) -> dict[str, Any]:
        return {
            "autocorrelation_steps": self.autocorrelation_steps,
            "acceptance_fraction": self.acceptance,
            "walkers": self.walkers,
            "steps": self.steps,
            "burn_in": self.burn_in,
            "converged": self.converged,
            "effective_samples": self.walkers * self.steps / max(self.autocorrelation_steps, 1.0),
            "likelihood_tempering": self.inflation,
            "sd_ms": float(np.std(self.samples_s)) * 1e3,
        }


@jax.jit
def _log_posterior(
    walkers: jax.Array,
    base: jax.Array,
    free: jax.Array,
    low: jax.Array,
    high: jax.Array,
    inflation: jax.Array,
    structure: model.Structure,
    data: model.FitData,
) -> jax.Array:
    """Log posterior of each walker (rows: free scaled parameters, then two log noise scales)."""
    count = free.shape[0]

    def one(position: jax.Array) -> jax.Array:
        params = base.at[free].set(position[:count])
        value = log_marginal(params, position[count:], inflation, structure, data)
        inside = jnp.all((position >= low) & (position <= high))
        return jnp.where(inside & jnp.isfinite(value), value, -jnp.inf)

    return jax.vmap(one)(walkers)


@in_float64
def sample_posterior(fit: SineFit, seed: int, steps: int = STEPS, burn_in: int = BURN_IN) -> Posterior:
    """Sample the latency's posterior under the fit's model, starting from the fit."""
    tempering = fit.lag_inflation * (fit.critical / NORMAL_95) ** 2
    free = np.flatnonzero(np.asarray(fit.structure.free) > 0)
    covariance = fit.covariance[np.ix_(free, free)] * tempering
    errors = np.sqrt(np.diag(covariance))
    noise_error = math.sqrt(tempering / (2 * fit.problem.count))
    centre = np.concatenate([fit.params[free], np.zeros(2)])
    low = np.concatenate([fit.params[free] - BOX_WIDTH * errors, np.full(2, LOG_NOISE_RANGE[0])])
    high = np.concatenate([fit.params[free] + BOX_WIDTH * errors, np.full(2, LOG_NOISE_RANGE[1])])
    lag = int(np.flatnonzero(free == model.PHASE_LAG)[0])
    low[lag] = max(low[lag], fit.params[model.PHASE_LAG] - math.pi)
    high[lag] = min(high[lag], fit.params[model.PHASE_LAG] + math.pi)
    gain = np.flatnonzero(free == model.GAIN)
    if gain.size:
        low[gain[0]] = max(low[gain[0]], 0.0)
    arguments = (
        jnp.asarray(fit.params),
        jnp.asarray(free),
        jnp.asarray(low),
        jnp.asarray(high),
        jnp.asarray(tempering),
        fit.structure,
        fit.problem.data,
    )

    interrupted: list[KeyboardInterrupt] = []

    def log_probability(walkers: np.ndarray) -> np.ndarray:
        # emcee prints a traceback of anything raised here before passing it on: an interrupt is
        # kept instead, and raised once the step ends.
        if not interrupted:
            try:
                return np.asarray(_log_posterior(jnp.asarray(walkers), *arguments))
            except KeyboardInterrupt as interrupt:
                interrupted.append(interrupt)
        return np.full(len(walkers), -np.inf)

    rng = np.random.default_rng(seed)
    start = np.tile(centre, (WALKERS, 1))
    start[:, : free.size] += rng.multivariate_normal(np.zeros(free.size), covariance, size=WALKERS, method="eigh")
    start[:, free.size :] += noise_error * rng.standard_normal((WALKERS, 2))
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(WALKERS, centre.size, log_probability, moves=moves, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    # The moves evaluate half the walkers at a time; so does the start, so one compilation serves.
    half = WALKERS // 2
    first = np.concatenate([log_probability(start[:half]), log_probability(start[half:])])
    for _ in sampler.sample(emcee.State(start, log_prob=first), iterations=burn_in + steps, progress=False):
        if interrupted:
            raise interrupted[0]
    chain = sampler.get_chain(discard=burn_in, flat=True)
    latency = chain[:, lag] * fit.problem.scales[model.PHASE_LAG]
    # tol=0: report the estimate without emcee's log message for short chains ("converged" says it).
    autocorrelation = float(np.max(sampler.get_autocorr_time(discard=burn_in, tol=0)))
    low_s, median_s, high_s = np.percentile(latency, [2.5, 50.0, 97.5])
    kept = latency[:: max(1, latency.size // KEPT_SAMPLES)]
    return Posterior(
        median_s=float(median_s),
        ci95_s=(float(low_s), float(high_s)),
        samples_s=kept,
        autocorrelation_steps=autocorrelation,
        acceptance=float(np.mean(sampler.acceptance_fraction)),
        walkers=WALKERS,
        steps=steps,
        burn_in=burn_in,
        inflation=tempering,
    )
