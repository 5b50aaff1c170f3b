"""What every estimator is given (``EstimationContext``) and what it must be (``Estimator``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, TypeVar

from analysis.cycles import CycleResolution, unwrap_near
from analysis.result import MethodResult
from analysis.swing import Swing

_Shared = TypeVar("_Shared")


class EstimationContext:
    """What the estimators of one analysis share.

    ``swing`` is the free swing, measured (signals, frequency, damping, per-period phases);
    ``cycles`` the whole number of periods chosen for the latency: every estimator reports a
    latency within half a period of ``cycles.reference_s`` (``unwrapped`` brings one there), so all
    take the same whole number of periods. ``seed`` seeds any randomness. An estimator appends its
    warnings for the user to ``warnings``. Work several estimators need (bayes samples around
    sinefit's fit) is computed once, by whichever asks first, through ``shared``.
    """

    def __init__(self, swing: Swing, cycles: CycleResolution, seed: int, warnings: list[str]) -> None:
        self.swing = swing
        self.cycles = cycles
        self.seed = seed
        self.warnings = warnings
        self._shared: dict[Callable[[EstimationContext], Any], Any] = {}

    def unwrapped(self, latency_s: float) -> float:
        """A latency known modulo the swing period, brought within half a period of the chosen one."""
        return unwrap_near(latency_s, self.cycles.reference_s, self.swing.period_s)

    def shared(self, compute: Callable[[EstimationContext], _Shared]) -> _Shared:
        """``compute(self)``, computed the first time any estimator asks for it and kept for the others."""
        if compute not in self._shared:
            self._shared[compute] = compute(self)
        return self._shared[compute]


class Estimator(Protocol):
    """A latency estimator: ``name`` is the ``method`` that asks for it, ``gives_interval`` whether
    its result has a 95 % interval, and ``estimate`` turns the shared context into its result
    (``MethodResult.method`` is ``name``; ``seconds`` the time the estimator itself took).

    An estimator may also have ``prepare()``, which loads what ``estimate`` will need (a heavy
    import): the pipeline calls it in the background while the video is tracked."""

    @property
    def name(self) -> str: ...

    @property
    def gives_interval(self) -> bool: ...

    def estimate(self, context: EstimationContext) -> MethodResult: ...
