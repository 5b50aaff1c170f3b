"""The predictor protocol and the table of predictors by name.

A predictor is a small stateful object driven once per tracker sample and once per display frame:

    predictor = make("slerp")
    predictor.update(sample)        # every tracker sample, in any order
    pose = predictor.predict(t)     # the pose expected at time t (s, rig clock)

A new predictor slots in by adding its class to `_PREDICTORS`, under its `name`, once it declares
its parameters (`predictors.params.declare_params`): `make` passes keyword parameters to the
constructor, which checks them against that declaration.

`DEFAULT` ("default") is not a predictor of its own but another name for the one to use when none
is named (`rig simulate`, `rig measure`): `make("default")` makes it, and `resolve` says which it is.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Any, Mapping, Protocol, runtime_checkable

from predictors.adaptive import Adaptive
from predictors.auto import Auto
from predictors.desp import DoubleExponentialSmoothing
from predictors.errors import PredictorError
from predictors.extrapolators import HoldLast, SlerpExtrapolator
from predictors.kalman import KalmanCA, KalmanCV
from predictors.params import ParamSet
from predictors.pose import Pose, PoseSample
from predictors.rls import RecursiveLeastSquares
from predictors.split import Split


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


_PREDICTORS: Mapping[str, Any] = MappingProxyType(
    {
        cls.name: cls
        for cls in (HoldLast, SlerpExtrapolator, KalmanCV, KalmanCA, DoubleExponentialSmoothing, Auto, Adaptive, Split,
                    RecursiveLeastSquares)
    }
)

DEFAULT = "default"
_DEFAULT_IS = RecursiveLeastSquares.name


def names() -> tuple[str, ...]:
    """The predictors `make` makes, each once (`make` also takes `DEFAULT`)."""
    return tuple(_PREDICTORS)


def resolve(name: str) -> str:
    """The predictor a name stands for: `name` itself, or the default predictor's for `DEFAULT`."""
    return _DEFAULT_IS if name == DEFAULT else name


def _predictor_class(name: str) -> Any:
    try:
        return _PREDICTORS[resolve(name)]
    except (KeyError, TypeError):
        raise PredictorError(
            f"unknown predictor {name!r}; known predictors: {', '.join(names())} ({DEFAULT!r} is {_DEFAULT_IS})"
        ) from None


def params_of(name: str) -> ParamSet:
    """The parameters predictor `name` takes: each one's unit, default, range and whether tuning fits it."""
    return _predictor_class(name).params


def make(name: str, **params: object) -> Predictor:
    """A new predictor called `name`, built with keyword `params`.

    Names and values are checked against the predictor's declaration (`params_of(name)`): an
    unknown name or a value outside its range is a PredictorError that lists the names taken or
    states the allowed range and unit.
    """
    return _predictor_class(name)(**params)
