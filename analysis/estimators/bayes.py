"""``bayes``: the latency's posterior by MCMC around sinefit's fit (``analysis.fit.posterior``)."""

from __future__ import annotations

import time

from analysis.estimators.contract import EstimationContext
from analysis.estimators.sinefit import joint_fit
from analysis.result import MethodResult


class BayesEstimator:
    """The posterior median and central 95 % interval of the lag, in the model sinefit chose."""

    name = "bayes"
    gives_interval = True

    def prepare(self) -> None:
        import analysis.fit.posterior  # noqa: F401

    def estimate(self, context: EstimationContext) -> MethodResult:
        # JAX and emcee are imported only when asked for: ``import analysis`` and sinefit never pay for them.
        from analysis.fit.posterior import sample_posterior

        fit = context.shared(joint_fit)
        started = time.perf_counter()
        posterior = sample_posterior(fit, context.seed)
        return MethodResult(
            self.name,
            posterior.median_s * 1e3,
            (posterior.ci95_s[0] * 1e3, posterior.ci95_s[1] * 1e3),
            fit.model,
            time.perf_counter() - started,
            posterior.details(),
            posterior,
        )
