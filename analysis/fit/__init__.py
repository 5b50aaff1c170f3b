"""The joint fit of both swings, in JAX: the model (``model``), its least-squares fit with model
choice and an honest interval (``least_squares``, the sinefit method) and its posterior by MCMC
(``posterior``, the bayes method).

Importing any of these imports JAX (and jaxopt, emcee), so the estimators import them only when a
fit is asked for. None of them changes a JAX setting on import: the fit needs 64-bit floats and
asks for them per call (``model.in_float64``).
"""
