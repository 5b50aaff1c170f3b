"""The joint fit of both swings: the model (``model``, one definition for numpy and JAX arrays),
its least-squares fit with model choice and an honest interval (``least_squares``, the sinefit
method: numpy only, Levenberg-Marquardt in ``levenberg_marquardt`` on the analytic Jacobians of
``jacobians``) and its posterior by MCMC (``posterior``, the bayes method, whose likelihood in JAX
is ``marginal``).

Only ``marginal`` and ``posterior`` import JAX (and emcee), so the default analysis never pays for
JAX; the bayes estimator imports them when it is asked for. Neither changes a JAX setting on
import: the posterior needs 64-bit floats and asks for them per call (``marginal.in_float64``).
"""
