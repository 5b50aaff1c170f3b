"""The predictor protocol and the table of predictors by name.

A predictor is a small stateful object driven once per tracker sample and once per display frame:

    predictor = make("slerp")
    predictor.update(sample)        # every tracker sample, in any order
    pose = predictor.predict(t)     # the pose expected at time t (s, rig clock)

A new predictor slots in by adding its class to `_PREDICTORS`; `make` passes keyword parameters to
its constructor after checking their names against the constructor's signature.
"""

from __future__ import annotations

import inspect
from types import MappingProxyType
from typing import Callable, Mapping, Protocol, runtime_checkable

from predictors.auto import Auto
from predictors.desp import DoubleExponentialSmoothing
from predictors.errors import PredictorError
from predictors.extrapolators import HoldLast, SlerpExtrapolator
from predictors.kalman import KalmanCA, KalmanCV
from predictors.pose import Pose, PoseSample


@runtime_checkable
class Predictor(Protocol):
    """Turns timestamped tracker samples into a pose for any requested time."""

    def update(self, sample: PoseSample) -> None:
        """Take one tracker sample (ordered by its sensor time); PredictorError, with the state
        unchanged, if it holds a non-finite value or a non-unit quaternion."""

    def predict(self, t: float) -> Pose:
        """The pose expected at time `t` (s), also before the newest sample; PredictorError before
        the first sample."""

    def reset(self) -> None:
        """Forget every sample, as if newly made."""


_PREDICTORS: Mapping[str, Callable[..., Predictor]] = MappingProxyType(
    {
        "hold": HoldLast,
        "slerp": SlerpExtrapolator,
        "kalman-cv": KalmanCV,
        "kalman-ca": KalmanCA,
        "desp": DoubleExponentialSmoothing,
        "auto": Auto,
    }
)


def names() -> tuple[str, ...]:
    """The names `make` accepts."""
    return tuple(_PREDICTORS)


def make(name: str, **params: object) -> Predictor:
    """A new predictor called `name`, built with keyword `params` (see the class for units)."""
    try:
        factory = _PREDICTORS[name]
    except (KeyError, TypeError):
        raise PredictorError(f"unknown predictor {name!r}; known predictors: {', '.join(names())}") from None
    accepted = [
        p.name
        for p in inspect.signature(factory).parameters.values()
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
    ]
    unknown = sorted(set(params) - set(accepted))
    if unknown:
        takes = ", ".join(accepted) if accepted else "no parameters"
        raise PredictorError(f"predictor {name!r} has no parameter {', '.join(unknown)}; it takes: {takes}")
    return factory(**params)
