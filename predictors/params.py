"""Predictor parameters, each declared once: what it means, its unit, default and allowed range,
whether tuning fits it, and how it maps to unconstrained space.

A predictor class lists its parameters with `declare_params`; its `params` (a `ParamSet`) is then
the one definition that everything else reads:

* the class's constructor takes them as keyword arguments and checks them (`ParamSet.assign`:
  defaults filled in, values outside their range refused with a `PredictorError` that names the
  range and unit, each parameter an attribute of the same name), and its docstring and signature
  list them with their units;
* `predictors.make` and `predictors.registry.params_of` find them by predictor name;
* the JAX twins build their parameter tuples from the values by these names
  (`predictors.jax_filters.predictions`);
* tuning fits the `trainable` ones in unconstrained coordinates through their `transform`
  (`predictors.tuning`): `LOG` for positive noises and rates, `LOGIT` for smoothing factors in
  (0, 1), None for what is set rather than fitted (time limits, thresholds).

A parameter several predictors share is one `Param` that each lists: the Kalman noises in
`predictors.kalman`, and here the sample rules `MAX_GAP` and `MAX_HORIZON`. A new predictor
declares its own beside its class and takes one line in `predictors.registry`:

    GAIN = Param("gain", 0.5, "", "Share of each innovation taken.", OPEN_UNIT, LOGIT, trainable=True)

    @declare_params(GAIN, MAX_GAP)
    class MyPredictor:
        name = "my-predictor"

        def __init__(self, **values: float | None) -> None:
            self.params.assign(self, values)

A parameter's `Range` (and the common ones, POSITIVE, NON_NEGATIVE, OPEN_UNIT) is the project's one
(`declared`), which the analyser's and the rig's settings use too. This module imports no JAX: the
transforms' JAX forms import it when tuning calls them.
"""

from __future__ import annotations

import inspect
import math
import textwrap
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Literal, Mapping, TypeVar

import numpy as np

from declared import NON_NEGATIVE, OPEN_UNIT, POSITIVE, Range
from predictors.errors import PredictorError


def _exp_jax(x: Any) -> Any:
    import jax.numpy as jnp  # only tuning calls this: the real-time path never imports JAX

    return jnp.exp(x)


def _sigmoid_jax(x: Any) -> Any:
    import jax  # as _exp_jax

    return jax.nn.sigmoid(x)


def _logit(value: float) -> Any:
    return np.log(value / (1.0 - value))


def _expit(x: Any) -> Any:
    return 1.0 / (1.0 + np.exp(-x))


@dataclass(frozen=True)
class Transform:
    """A bijection from `domain` onto the real line, so an optimiser can search without bounds.

    `to_unconstrained` and `to_natural` take numbers or numpy arrays; `to_natural_jax` is the same
    inverse for JAX values (traceable, differentiable), which tuning runs inside its loss.
    """

    name: str
    domain: Range
    to_unconstrained: Callable[[Any], Any]
    to_natural: Callable[[Any], Any]
    to_natural_jax: Callable[[Any], Any]


LOG = Transform("log", POSITIVE, np.log, np.exp, _exp_jax)
LOGIT = Transform("logit", OPEN_UNIT, _logit, _expit, _sigmoid_jax)


@dataclass(frozen=True)
class Param:
    """One parameter of a predictor.

    name: the keyword argument and attribute.
    default: the value when none is given; None means "not given" is itself a setting (the
        class's docstring says what it does), and then None is accepted as a value too.
    unit: as a user reads it in messages ("metres", "1/s"); "" for a pure number.
    doc: what it does, one or two sentences.
    range: the values accepted.
    transform: its map to unconstrained space for tuning; None for a parameter that is set, not fitted.
    trainable: whether tuning fits it (it then needs a transform).
    acts_on: the part of the pose it shapes; tuning reports it fitted only where that part moved.
    tune_from: where tuning starts when the given value is outside the transform's domain (a
        damping of 0, whose log is no starting point).
    """

    name: str
    default: float | None
    unit: str
    doc: str
    range: Range
    transform: Transform | None = None
    trainable: bool = False
    acts_on: Literal["position", "orientation", "pose"] = "pose"
    tune_from: float | None = None

    def __post_init__(self) -> None:
        if self.trainable and self.transform is None:
            raise ValueError(f"parameter {self.name!r} is trainable, so it needs a transform")

    def check(self, value: Any, predictor: str) -> float | None:
        """`value` as a float, or PredictorError naming the parameter, its range and unit."""
        if value is None and self.default is None:
            return None
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if not self.range.contains(number):
            raise PredictorError(f"{predictor}: {self.name} must be {self._allowed()}, got {value!r}")
        return number

    def describe(self) -> str:
        """One line for a docstring: name, range with unit, default, whether tuning fits it, doc."""
        fitted = "; fitted by tuning" if self.trainable else ""
        if self.trainable and self.tune_from is not None and self.transform is not None:
            fitted += f" (from {self.tune_from:g} where the {self.transform.name} of the value is undefined)"
        return f"{self.name}: {self._allowed()}; default {self.default!r}{fitted}. {self.doc}"

    def _allowed(self) -> str:
        return self.range.describe(self.unit) + (" or None" if self.default is None else "")


class ParamSet:
    """The parameters of one predictor, in the order its docstring lists them."""

    def __init__(self, predictor: str, params: tuple[Param, ...]) -> None:
        names = [p.name for p in params]
        if len(set(names)) != len(names):
            raise ValueError(f"predictor {predictor!r} declares a parameter twice: {names}")
        self.predictor = predictor
        self._params = {p.name: p for p in params}

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter's name."""
        return tuple(self._params)

    @property
    def trainable(self) -> tuple[Param, ...]:
        """The parameters tuning fits, in declaration order."""
        return tuple(p for p in self._params.values() if p.trainable)

    def __iter__(self) -> Iterator[Param]:
        return iter(self._params.values())

    def resolve(self, given: Mapping[str, Any]) -> dict[str, float | None]:
        """Every parameter's value: `given`, checked, else the default. PredictorError for a name
        the predictor does not take (listing those it does) or a value outside its range."""
        unknown = sorted(set(given) - set(self._params))
        if unknown:
            takes = ", ".join(self._params) if self._params else "no parameters"
            raise PredictorError(
                f"predictor {self.predictor!r} has no parameter {', '.join(unknown)}; it takes: {takes}"
            )
        return {
            name: param.check(given[name], self.predictor) if name in given else param.default
            for name, param in self._params.items()
        }

    def assign(self, instance: object, given: Mapping[str, Any]) -> None:
        """Set every parameter (`resolve`d from `given`) as an attribute of `instance`."""
        for name, value in self.resolve(given).items():
            setattr(instance, name, value)

    def signature(self) -> inspect.Signature:
        """The keyword-only signature of a constructor that takes these parameters."""
        return inspect.Signature(
            [inspect.Parameter(p.name, inspect.Parameter.KEYWORD_ONLY, default=p.default) for p in self]
        )

    def describe(self, indent: str = "    ") -> str:
        """The parameter list for the class docstring, wrapped at 100 columns."""
        if not self._params:
            return f"{indent}Parameters: none."
        lines = [f"{indent}Parameters (keyword arguments; `params` declares them):"]
        for param in self:
            lines += textwrap.wrap(
                param.describe(), 100, initial_indent=indent * 2, subsequent_indent=indent * 3
            )
        return "\n".join(lines)


PredictorClass = TypeVar("PredictorClass", bound=type)


def declare_params(*params: Param) -> Callable[[PredictorClass], PredictorClass]:
    """Class decorator: the predictor (with a `name`) takes `params` as keyword arguments.

    Sets the class's `params` (a `ParamSet`) and `__signature__`, and appends the parameter list
    to its docstring, so that help() shows every parameter with its unit, range and default.
    The constructor calls `self.params.assign(self, values)`.
    """

    def declare(cls: PredictorClass) -> PredictorClass:
        declared = ParamSet(cls.name, params)  # type: ignore[attr-defined]
        cls.params = declared  # type: ignore[attr-defined]
        cls.__signature__ = declared.signature()  # type: ignore[attr-defined]
        cls.__doc__ = f"{(cls.__doc__ or '').rstrip()}\n\n{declared.describe()}\n"
        return cls

    return declare


MAX_GAP = Param(
    "max_gap", 1.0, "seconds", "A longer gap between samples restarts the predictor from the sample after it.",
    Range(0.0, 86400.0, includes_high=True),
)
MAX_HORIZON = Param(
    "max_horizon", 0.5, "seconds",
    "Predictions further than this from the newest sample (either way) are made for this horizon: "
    "a drop-out holds the motion instead of flying away.",
    Range(0.0, 10.0, includes_high=True),
)
