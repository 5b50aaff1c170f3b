"""The joint least-squares fit (``sinefit``): both swings with a shared frequency, damping and chirp.

The model is in ``analysis.fit.model``; its lag parameter is the latency. The fit is numpy's
and imports no JAX: Levenberg-Marquardt (``analysis.fit.levenberg_marquardt``) on the projected
residual, with analytic Jacobians (``analysis.fit.jacobians``). It runs on the signals averaged in
bins of a few frames (about BINS_PER_PERIOD bins per swing period; see ``analysis.signals.binned``),
padded to a power-of-two length so that one JAX compilation of the posterior's likelihood serves
every clip of similar length. Each bin is weighted by sqrt(frames in it) / (the signal's noise);
after a first fit of the richest model each signal's weights are rescaled to make its weighted
residuals' RMS one, so the LED and the sphere count by how well each is actually measured.

Model choice. Six models range from a pure sine (frequency, lag and gain only) to a damped,
chirping sine with second and third harmonics and slow quadratic drift of each signal; the one
with the lowest BIC = chi^2 / k + p ln(n / k) is reported, where n is the number of bins, p the
number of parameters and k the variance inflation below (correlated residuals carry less
information than as many independent ones, so both the misfit and the sample size are deflated).
The richest model is fitted first; the Wald test of the parameters a simpler model drops
predicts that model's BIC, and models predicted to lose by more than SCREEN_MARGIN are not fitted.

Uncertainty. The residuals of a fit to real tracks are not white (the display's staircase,
unmodelled harmonics, compression), so the Jacobian's standard error, which assumes they are, is
wrong, too small where the residuals' power gathers near the swing frequency and too large where
it lies elsewhere. The variance of the latency is instead the Newey-West (Bartlett-window) long-run
variance of its influence series h_i = r_i (J_i . A^-1 e_lag), summed over both signals frame by
frame, with a bandwidth of one swing period: a sandwich estimator that is right for residuals
correlated over up to a period. The ratio of the two variances is the inflation k. The interval
uses the fixed-b critical value for that bandwidth (Kiefer and Vogelsang 2005): with only a few
periods in the clip the variance itself is uncertain and the interval must be wider.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from analysis.fit import model
from analysis.fit.jacobians import full_jacobian, projected_residual_and_jacobian
from analysis.fit.levenberg_marquardt import levenberg_marquardt
from analysis.longrun import long_run_variance
from analysis.signals import BinnedSignals, SwingSignals, binned

BINS_PER_PERIOD = 16
MIN_PADDED = 256
# Two-sided 95 % critical value of a Bartlett-kernel HAC t-statistic whose bandwidth is the
# fraction b of the sample (Kiefer and Vogelsang 2005, fixed-b asymptotics): 1.96 + c1 b + c2 b^2
# + c3 b^3. A clip of a few periods has b near 1/3 and needs about 3 rather than 1.96.
FIXED_B_CRITICAL = (1.959963984540054, 2.9694, 0.4160, -0.5324)

MODELS: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {
    # name: (free non-linear parameters, linear coefficients)
    "sine": ((model.CYCLES, model.PHASE_LAG, model.GAIN), model.FUNDAMENTAL),
    "sine+drift": ((model.CYCLES, model.PHASE_LAG, model.GAIN), model.FUNDAMENTAL + model.DRIFT),
    "damped": (tuple(range(5)), model.FUNDAMENTAL),
    "damped+drift": (tuple(range(5)), model.FUNDAMENTAL + model.DRIFT),
    "damped+harmonics": (tuple(range(5)), model.FUNDAMENTAL + model.HARMONICS),
    "damped+harmonics+drift": (tuple(range(5)), model.FUNDAMENTAL + model.HARMONICS + model.DRIFT),
}
RICHEST = "damped+harmonics+drift"
# The sandwich's Bartlett window spans this many swing periods of residuals.
HAC_PERIODS = 1.0
# Models whose Wald-approximated BIC exceeds the best by more than this are not fitted.
SCREEN_MARGIN = 20.0
# Levenberg-Marquardt: iterations and the relative step at which it stops.
MAX_ITERATIONS = 60
STEP_TOLERANCE = 1e-11


@dataclass(frozen=True)
class Guess:
    """Starting values: frequency (Hz), damping rate (1/s), chirp zeta (rad/s^2), latency (s), gain."""

    frequency_hz: float
    damping: float
    chirp: float
    latency_s: float
    gain: float


@dataclass(frozen=True)
class FitProblem:
    """A fit set up: data, the bins it came from, and how scaled parameters map to physical ones."""

    data: model.FitData
    bins: BinnedSignals
    count: int
    span: float
    mid: float
    scales: np.ndarray
    period_bins: float


@dataclass(frozen=True)
class SineFit:
    """The chosen model's fit. latency_s, se_s in s; ci95_s is latency +- critical se, critical the
    fixed-b value for the sandwich's bandwidth (1.96 for a long clip, about 3 for three periods).

    ci95_s allows for what the residuals show. An error common to the whole clip, such as the bias
    of the camera's sampling of the display, is not in them; ``analysis.sampling`` corrects or allows
    for it in the interval ``analysis.estimation.estimate`` reports, which is the one to quote. On
    simulated clips of 2.5 to 10 periods ci95_s held the rig's 30-second latency in 81 to 96 % of
    clips, the reported interval in 94 to 100 %. On a few periods (latency_s - truth) / se_s has
    heavy tails, a standard deviation of about 1.6 at three periods where the interval is exact:
    judge the interval by its coverage, not by that spread against 1.96."""

    latency_s: float
    se_s: float
    ci95_s: tuple[float, float]
    critical: float
    model: str
    frequency_hz: float
    damping: float
    chirp: float
    gain: float
    inflation: float
    naive_se_s: float
    residual_rms_px: tuple[float, float]
    bic: dict[str, float]
    bic_screened: dict[str, float]
    iterations: int
    params: np.ndarray
    structure: model.Structure
    problem: FitProblem
    covariance: np.ndarray

    @property
    def lag_inflation(self) -> float:
        """The chosen model's variance inflation of the latency: (se / white-noise se)^2."""
        return (self.se_s / self.naive_se_s) ** 2

    def curves(self) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """For the LED, then the sphere: (bin times, binned values, fitted values) over used bins."""
        data = self.problem.data
        coefficients, _ = model.linear_solution(self.params, self.structure, data)
        fitted = model.design(self.params, self.structure, data) @ coefficients
        n = data.tau.shape[0] // 2
        times = data.tau + self.problem.mid
        used = data.w > 0
        values = data.y
        return tuple(
            (times[s][used[s]], values[s][used[s]], fitted[s][used[s]]) for s in (slice(0, n), slice(n, 2 * n))
        )


def frames_per_bin(frame_interval: float, period_s: float) -> int:
    """How many frames to average per bin so that a period holds about BINS_PER_PERIOD bins."""
    return max(1, int(period_s / frame_interval // BINS_PER_PERIOD))


def make_problem(signals: SwingSignals, noise: tuple[float, float], guess: Guess) -> FitProblem:
    """Bin, weight and pad the signals; scale the parameters around the guess."""
    period = 1.0 / guess.frequency_hz
    bins = binned(signals, frames_per_bin(signals.frame_interval, period))
    count = bins.led_t.size
    padded = max(MIN_PADDED, 1 << math.ceil(math.log2(count)))
    start, end = signals.t[0], signals.t[-1]
    span = float(end - start)
    mid = float(start + end) / 2
    tau = np.zeros(2 * padded)
    y = np.zeros(2 * padded)
    w = np.zeros(2 * padded)
    for offset, t, values, number, sigma in (
        (0, bins.led_t, bins.led, bins.led_count, noise[0]),
        (padded, bins.sphere_t, bins.sphere, bins.sphere_count, noise[1]),
    ):
        valid = number > 0
        tau[offset : offset + count] = np.where(valid, t - mid, 0.0)
        y[offset : offset + count] = np.where(valid, values, 0.0)
        w[offset : offset + count] = np.where(valid, np.sqrt(number) / max(sigma, 1e-9), 0.0)
    omega = 2 * math.pi * guess.frequency_hz
    scales = np.array([2 * math.pi / span, 1 / span, 1 / span**2, 1 / omega, 1.0])
    data = model.FitData(tau, y, w, np.asarray(span / 2), scales)
    return FitProblem(data, bins, count, span, mid, scales, period / (bins.frames_per_bin * signals.frame_interval))


def structure_of(name: str, start: np.ndarray) -> model.Structure:
    free_indices, linear_indices = MODELS[name]
    free = np.zeros(5)
    free[list(free_indices)] = 1.0
    linear = np.zeros(16)
    linear[list(linear_indices)] = 1.0
    fixed = np.where(free > 0, start, 0.0)
    fixed[model.CYCLES] = start[model.CYCLES]
    fixed[model.GAIN] = start[model.GAIN]
    return model.Structure(free, fixed, linear)


def scaled_guess(guess: Guess, problem: FitProblem) -> np.ndarray:
    physical = np.array([2 * math.pi * guess.frequency_hz, guess.damping, guess.chirp, guess.latency_s, guess.gain])
    return physical / problem.scales


def _fit(params: np.ndarray, structure: model.Structure, data: model.FitData) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Levenberg-Marquardt from ``params``: (scaled parameters, coefficients, residual, iterations)."""
    solution = levenberg_marquardt(
        lambda x: model.projected_residual(x, structure, data),
        lambda x: projected_residual_and_jacobian(x, structure, data),
        params,
        MAX_ITERATIONS,
        STEP_TOLERANCE,
    )
    coefficients, residual = model.linear_solution(solution.params, structure, data)
    return solution.params, coefficients, residual, solution.iterations


def _variances(params: np.ndarray, coefficients: np.ndarray, structure: model.Structure, problem: FitProblem) -> tuple[float, float, np.ndarray]:
    """(sandwich variance, white-noise variance) of the scaled lag parameter, and the white-noise
    covariance of all 5 + 16 parameters (zero for those the structure leaves out): the inverse
    Gauss-Newton information times the residual variance."""
    jacobian = full_jacobian(params, coefficients, structure, problem.data)
    residual = model.full_residual(np.concatenate([params, coefficients]), structure, problem.data)
    active = np.concatenate([structure.free, structure.linear]) > 0
    reduced = jacobian[:, active]
    information = reduced.T @ reduced
    covariance = np.linalg.inv(information)
    lag_index = int(np.count_nonzero(active[: model.PHASE_LAG]))
    direction = covariance[:, lag_index]
    influence = residual * (reduced @ direction)
    n = problem.data.tau.shape[0] // 2
    per_bin = influence[:n] + influence[n:]
    dof = max(int(np.count_nonzero(problem.data.w > 0)) - int(np.count_nonzero(active)), 1)
    residual_variance = float(residual @ residual) / dof
    naive = float(covariance[lag_index, lag_index]) * residual_variance
    sandwich = long_run_variance(per_bin[: problem.count], _bandwidth(problem))
    full = np.zeros((active.size, active.size))
    full[np.ix_(active, active)] = covariance * residual_variance
    return sandwich, naive, full


def _reweighted(problem: FitProblem, residual: np.ndarray) -> FitProblem:
    """The problem with each signal's weights rescaled so that its weighted residuals have unit RMS.

    The first weights come from per-frame scatter; what a bin average keeps of it (a display's
    staircase, say, mostly cancels within a bin) is only known once the model is fitted.
    """
    weights = problem.data.w.copy()
    n = weights.size // 2
    for block in (slice(0, n), slice(n, 2 * n)):
        used = weights[block] > 0
        rms = math.sqrt(float(np.mean(residual[block][used] ** 2))) if np.any(used) else 1.0
        weights[block] /= max(rms, 1e-12)
    return replace(problem, data=problem.data._replace(w=weights))


def _bandwidth(problem: FitProblem) -> int:
    return max(1, min(round(HAC_PERIODS * problem.period_bins), problem.count - 1))


def critical_value(fraction: float) -> float:
    """The fixed-b 95 % critical value for a Bartlett bandwidth that is ``fraction`` of the sample."""
    return float(np.polyval(FIXED_B_CRITICAL[::-1], fraction))


def _bic(chi2: float, parameters: int, bins: int, inflation: float) -> float:
    return chi2 / inflation + parameters * math.log(bins / inflation)


def _parameter_count(name: str) -> int:
    return len(MODELS[name][0]) + len(MODELS[name][1])


def _dropped(name: str) -> np.ndarray:
    """Indices, among the richest model's 5 + 16 parameters, that model ``name`` holds at zero."""
    free, linear = MODELS[name]
    nonlinear = [i for i in (model.DAMPING, model.CHIRP) if i not in free]
    return np.array(nonlinear + [5 + i for i in range(16) if i not in linear], dtype=int)


def _screened_bic(
    values: np.ndarray, covariance: np.ndarray, richest_bic: float, bins: int, inflation: float
) -> dict[str, float]:
    """Each simpler model's BIC as the Wald approximation from the richest fit predicts it: its
    chi-square exceeds the richest's by about theta_d' C_dd^-1 theta_d over the parameters d it
    drops (held at zero)."""
    approximate = {}
    for name in MODELS:
        dropped = _dropped(name)
        if dropped.size == 0:
            continue
        theta = values[dropped]
        wald = float(theta @ np.linalg.solve(covariance[np.ix_(dropped, dropped)], theta))
        approximate[name] = richest_bic + wald / inflation - dropped.size * math.log(bins / inflation)
    return approximate


def fit_sine(signals: SwingSignals, noise: tuple[float, float], guess: Guess) -> SineFit:
    """Fit the models, choose by BIC, and return the chosen model's latency with its uncertainty.

    The richest model is fitted first; a simpler one is fitted too unless the Wald approximation
    already puts its BIC more than SCREEN_MARGIN above the best (it would not be chosen).
    """
    problem = make_problem(signals, noise, guess)
    start = scaled_guess(guess, problem)
    bins_used = int(np.count_nonzero(problem.data.w > 0))
    fits = {}
    params, _, residual, _ = _fit(start, structure_of(RICHEST, start), problem.data)
    problem = _reweighted(problem, residual)
    fits[RICHEST] = _fit(params, structure_of(RICHEST, start), problem.data)
    richest_params = fits[RICHEST][0]
    sandwich, naive, covariance = _variances(richest_params, fits[RICHEST][1], structure_of(RICHEST, richest_params), problem)
    inflation = max(1.0, sandwich / naive)
    bic = {RICHEST: _bic(float(fits[RICHEST][2] @ fits[RICHEST][2]), _parameter_count(RICHEST), bins_used, inflation)}
    screened = _screened_bic(
        np.concatenate([richest_params, fits[RICHEST][1]]), covariance, bic[RICHEST], bins_used, inflation
    )
    best_guess = min([bic[RICHEST], *screened.values()])
    for name, approximate in screened.items():
        if approximate > best_guess + SCREEN_MARGIN:
            continue
        structure = structure_of(name, richest_params)
        fits[name] = _fit(richest_params, structure, problem.data)
        bic[name] = _bic(float(fits[name][2] @ fits[name][2]), _parameter_count(name), bins_used, inflation)
    chosen = min(bic, key=bic.__getitem__)
    params, coefficients, residual, iterations = fits[chosen]
    structure = structure_of(chosen, richest_params)
    sandwich, naive, covariance = _variances(params, coefficients, structure, problem)
    critical = critical_value(_bandwidth(problem) / problem.count)
    physical = model.physical(params, structure, problem.data)
    se = math.sqrt(sandwich) * problem.scales[model.PHASE_LAG]
    latency = float(physical[model.PHASE_LAG])
    n = problem.data.tau.shape[0] // 2
    w = problem.data.w
    rms = tuple(
        float(np.sqrt(np.sum((residual[s] / np.where(w[s] > 0, w[s], 1.0)) ** 2 * (w[s] > 0)) / max(np.count_nonzero(w[s] > 0), 1)))
        for s in (slice(0, n), slice(n, 2 * n))
    )
    return SineFit(
        latency_s=latency,
        se_s=se,
        ci95_s=(latency - critical * se, latency + critical * se),
        critical=critical,
        model=chosen,
        frequency_hz=float(physical[model.CYCLES]) / (2 * math.pi),
        damping=float(physical[model.DAMPING]),
        chirp=float(physical[model.CHIRP]),
        gain=float(physical[model.GAIN]),
        inflation=inflation,
        naive_se_s=math.sqrt(naive) * problem.scales[model.PHASE_LAG],
        residual_rms_px=rms,
        bic=bic,
        bic_screened={name: value for name, value in screened.items() if name not in bic},
        iterations=iterations,
        params=params,
        structure=structure,
        problem=problem,
        covariance=covariance,
    )
