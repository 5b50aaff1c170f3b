"""``sinefit``, the default: the joint least-squares fit of both swings (``analysis.fit.least_squares``)."""

from __future__ import annotations

import time

from analysis.caveat import caveat
from analysis.estimators.contract import EstimationContext
from analysis.fit.least_squares import Guess, SineFit, fit_sine
from analysis.result import MethodResult
from analysis.windows import gain_ratio


def joint_fit(context: EstimationContext) -> SineFit:
    """The joint fit, started from the swing as measured and the chosen whole number of periods;
    shared through ``context.shared`` (bayes samples around it). A warning says when the fit moved
    the latency by more than a quarter period from where it started."""
    swing, reference = context.swing, context.cycles.reference_s
    guess = Guess(swing.frequency_hz, swing.damping, 0.0, reference, gain_ratio(swing.windows))
    fit = fit_sine(swing.signals, (swing.windows.led_noise, swing.windows.sphere_noise), guess)
    if abs(fit.latency_s - reference) > swing.period_s / 4:
        context.warnings.append(caveat(
            f"the fit moved the latency from {reference * 1e3:.1f} to {fit.latency_s * 1e3:.1f} ms, more than a quarter "
            "of a swing from where the phases put it",
            "check the tracks in the plot (--plot), and give --latency-range LOW,HIGH if the lab knows the latency's range",
        ))  # fmt: skip
    return fit


class SineFitEstimator:
    """The lag of the joint fit, with its 95 % interval, in the model chosen by BIC."""

    name = "sinefit"
    gives_interval = True

    def estimate(self, context: EstimationContext) -> MethodResult:
        started = time.perf_counter()
        fit = context.shared(joint_fit)
        return MethodResult(
            self.name,
            fit.latency_s * 1e3,
            (fit.ci95_s[0] * 1e3, fit.ci95_s[1] * 1e3),
            fit.model,
            time.perf_counter() - started,
            {
                "se_ms": fit.se_s * 1e3,
                "se_white_noise_ms": fit.naive_se_s * 1e3,
                "variance_inflation": fit.lag_inflation,
                "bic_inflation": fit.inflation,
                "frequency_hz": fit.frequency_hz,
                "damping_per_s": fit.damping,
                "chirp_rad_per_s2": fit.chirp,
                "gain": fit.gain,
                "residual_rms_px": {"led": fit.residual_rms_px[0], "sphere": fit.residual_rms_px[1]},
                "bic": fit.bic,
                "bic_wald_screened": fit.bic_screened,
                "iterations": fit.iterations,
                "frames_per_bin": fit.problem.bins.frames_per_bin,
            },
            fit,
        )
