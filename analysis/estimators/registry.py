"""The estimators ``estimate`` and ``analyse`` know, by name, in the order they run and are reported.

The built-in ones are listed in ``_estimators`` below: adding one is its module in this package
and one entry there. A lab's own estimator (or a test's) is added from outside the package with
``register_estimator`` and taken away with ``unregister_estimator``; it then runs under its name
and with ``method="all"``, after the built-in ones, and the command line offers it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from analysis.errors import AnalysisError

if TYPE_CHECKING:
    from analysis.estimators.contract import Estimator

DEFAULT_METHOD = "sinefit"
# The method that asks for every estimator; its result is the default method's.
ALL = "all"

_estimators: dict[str, Estimator | str] = {
    "fft": "analysis.estimators.fft:FftPhaseEstimator",
    "xcorr": "analysis.estimators.xcorr:CrossCorrelationEstimator",
    "sinefit": "analysis.estimators.sinefit:SineFitEstimator",
    "bayes": "analysis.estimators.bayes:BayesEstimator",
}
"""Every estimator by name, in the order they run: a built-in one as "module:Class" until it is
first asked for, so that naming the methods (the command line's options) imports none of them."""


def _made(name: str) -> Estimator:
    estimator = _estimators[name]
    if isinstance(estimator, str):
        module, _, kind = estimator.partition(":")
        estimator = _estimators[name] = getattr(importlib.import_module(module), kind)()
    return estimator


def methods() -> tuple[str, ...]:
    """The registered estimators' names, in the order they run."""
    return tuple(_estimators)


def estimators_for(method: str) -> tuple[Estimator, ...]:
    """The estimators ``method`` asks for: the one of that name, or every one for ALL.
    AnalysisError for a name no estimator has."""
    if method == ALL:
        return tuple(map(_made, _estimators))
    if method not in _estimators:
        raise AnalysisError(f"unknown method {method!r}; choose one of {', '.join(_estimators)} or {ALL}")
    return (_made(method),)


def register_estimator(estimator: Estimator) -> None:
    """Make ``estimator`` available under its name, after those already registered.

    ValueError if the name is taken (or is ALL), or if the object does not meet the contract.
    """
    name = getattr(estimator, "name", None)
    if not isinstance(name, str) or not name or name == ALL:
        raise ValueError(f"an estimator needs a name other than {ALL!r}, not {name!r}")
    if name in _estimators:
        raise ValueError(f"an estimator named {name!r} is already registered; unregister it first")
    if not isinstance(getattr(estimator, "gives_interval", None), bool) or not callable(getattr(estimator, "estimate", None)):
        raise ValueError(f"estimator {name!r} needs a bool gives_interval and an estimate(context) method")
    _estimators[name] = estimator


def unregister_estimator(name: str) -> None:
    """Take the estimator called ``name`` away; ValueError if none is registered under it."""
    if name not in _estimators:
        raise ValueError(f"no estimator named {name!r} is registered")
    del _estimators[name]
