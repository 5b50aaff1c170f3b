"""Predictor parameters, declared once (`predictors.params`): every predictor's constructor, docstring,
`make` and tuning read the one declaration; transforms invert; bad values name their range."""

import inspect
import math
import re

import jax
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from declared import Range
from predictors import PoseSample, PredictorError, make, names
from predictors.params import LOG, LOGIT, NON_NEGATIVE, OPEN_UNIT, Param, declare_params
from predictors.registry import params_of

laws = settings(deadline=None, max_examples=50, derandomize=True)
DECLARED = [(name, param) for name in names() for param in params_of(name)]


def outside(param: Param) -> float:
    """A value just outside the parameter's range."""
    return param.range.low if not param.range.includes_low else math.nextafter(param.range.low, -math.inf)


@pytest.mark.parametrize(("name", "param"), DECLARED, ids=[f"{n}.{p.name}" for n, p in DECLARED])
def test_each_parameter_becomes_an_attribute_with_its_declared_default(name, param):
    assert getattr(make(name), param.name) == param.default
    assert param.default is None or param.range.contains(param.default)


@pytest.mark.parametrize(("name", "param"), DECLARED, ids=[f"{n}.{p.name}" for n, p in DECLARED])
def test_a_value_outside_the_range_is_an_error_naming_the_parameter_range_and_unit(name, param):
    value = outside(param)
    message = f"{name}: {param.name} must be {param.range.describe(param.unit)}"
    with pytest.raises(PredictorError, match=f"^{re.escape(message)}.*, got {re.escape(repr(value))}$"):
        make(name, **{param.name: value})
    if param.unit:
        assert f"of {param.unit}" in message


@pytest.mark.parametrize(("name", "param"), DECLARED, ids=[f"{n}.{p.name}" for n, p in DECLARED])
def test_only_a_parameter_that_defaults_to_none_takes_none(name, param):
    if param.default is None:
        assert getattr(make(name, **{param.name: None}), param.name) is None
    else:
        with pytest.raises(PredictorError, match=f"{param.name} must be"):
            make(name, **{param.name: None})


@pytest.mark.parametrize("name", names())
def test_the_class_signature_and_docstring_come_from_the_declaration(name):
    declared = params_of(name)
    cls = type(make(name))
    signature = inspect.signature(cls)
    assert [(p.name, p.default, p.kind) for p in signature.parameters.values()] == [
        (param.name, param.default, inspect.Parameter.KEYWORD_ONLY) for param in declared
    ]
    doc = " ".join(inspect.getdoc(cls).split())
    for param in declared:
        assert f"{param.name}: {param.range.describe(param.unit)}" in doc


@pytest.mark.parametrize(("name", "param"), DECLARED, ids=[f"{n}.{p.name}" for n, p in DECLARED])
def test_tuning_can_start_a_trainable_parameter_from_anywhere_in_its_range(name, param):
    if not param.trainable:
        return
    transform = param.transform
    assert transform is not None
    edge_needs_a_start = param.range.includes_low and not transform.domain.contains(param.range.low)
    assert not edge_needs_a_start or transform.domain.contains(param.tune_from)


def _ends(param: Param) -> list[float]:
    """The largest and smallest values the parameter takes (an open end approached within 1e-9 of it)."""
    low = param.range.low if param.range.includes_low else param.range.low + 1e-9 * max(1.0, abs(param.range.low))
    high = param.range.high if param.range.includes_high else math.nextafter(param.range.high, 0.0)
    return [low, high]


@pytest.mark.parametrize(("name", "param"), DECLARED, ids=[f"{n}.{p.name}" for n, p in DECLARED])
def test_every_parameter_has_a_finite_range_whose_ends_predict_finite_poses(name, param):
    assert math.isfinite(param.range.low) and math.isfinite(param.range.high)
    for value in _ends(param):
        predictor = make(name, **{param.name: value})
        for k in range(40):
            t = 0.01 * k
            predictor.update(PoseSample(t, t, (math.sin(t), 0.0, 1.0), (math.cos(t / 2), 0.0, 0.0, math.sin(t / 2))))
        pose = predictor.predict(0.45)
        assert np.all(np.isfinite(pose.position)) and np.all(np.isfinite(pose.orientation)), (param.name, value)


def test_a_value_far_past_a_noise_s_range_is_refused_not_overflowed():
    with pytest.raises(PredictorError, match="position_noise must be a positive number of metres from 1e-09 to 1, got 1e\\+200"):
        make("kalman-cv", position_noise=1e200)


@pytest.mark.parametrize(("value", "clipped"), [(-5.0, 0.0), (0.5, 0.5), (1e9, 1e4)])
def test_a_closed_range_clips_a_value_onto_its_ends(value, clipped):
    assert Range(0.0, 1e4, True, True).clipped(value) == clipped


def test_an_open_end_leaves_a_value_past_it_as_it_is():
    assert Range(0.0, 1.0).clipped(-1.0) == -1.0 and Range(0.0, 1.0).clipped(2.0) == 2.0


def test_values_are_floats_and_unknown_names_list_the_accepted_ones():
    assert params_of("desp").resolve({"position_alpha": 1 / 4}) == {
        "position_alpha": 0.25, "orientation_alpha": 0.5, "sample_interval": None, "max_gap": 1.0, "max_horizon": 0.5,
    }
    assert type(make("kalman-cv", max_gap=2).max_gap) is float
    with pytest.raises(PredictorError, match="predictor 'desp' has no parameter alpha, beta; it takes: position_alpha, "):
        params_of("desp").resolve({"beta": 1.0, "alpha": 0.5})
    with pytest.raises(PredictorError, match="unknown predictor 'kalman'"):
        params_of("kalman")


@given(st.floats(1e-12, 1e12))
@laws
def test_log_maps_positive_values_there_and_back(value):
    assert LOG.to_natural(LOG.to_unconstrained(value)) == pytest.approx(value, rel=1e-14)


@given(st.floats(1e-9, 1.0 - 1e-9))
@example(0.5)
@laws
def test_logit_maps_smoothing_factors_there_and_back(value):
    assert LOGIT.to_natural(LOGIT.to_unconstrained(value)) == pytest.approx(value, rel=1e-9)


@given(st.floats(-30.0, 30.0))
@example(0.0)
@laws
def test_the_jax_inverses_are_the_numpy_ones(x):
    with jax.enable_x64(True):
        for transform in (LOG, LOGIT):
            assert float(transform.to_natural_jax(np.float64(x))) == pytest.approx(float(transform.to_natural(x)), rel=1e-15)


def test_a_trainable_parameter_needs_a_transform_and_a_set_no_repeats():
    with pytest.raises(ValueError, match="'gain' is trainable, so it needs a transform"):
        Param("gain", 0.5, "", "Share of each innovation taken.", OPEN_UNIT, trainable=True)
    gain = Param("gain", 0.5, "", "Share of each innovation taken.", OPEN_UNIT, LOGIT, trainable=True)
    with pytest.raises(ValueError, match="declares a parameter twice"):

        @declare_params(gain, gain)
        class Twice:
            name = "twice"


def test_a_new_predictor_declares_its_parameters_once():
    gain = Param("gain", 0.5, "", "Share of each innovation taken.", OPEN_UNIT, LOGIT, trainable=True)
    delay = Param("delay", 0.01, "seconds", "Transport delay to add.", NON_NEGATIVE)

    @declare_params(gain, delay)
    class Toy:
        """A toy predictor."""

        name = "toy"

        def __init__(self, **values):
            self.params.assign(self, values)

    toy = Toy(delay=0.02)
    assert (toy.gain, toy.delay) == (0.5, 0.02)
    assert [p.name for p in Toy.params.trainable] == ["gain"]
    assert str(inspect.signature(Toy)) == "(*, gain=0.5, delay=0.01)"
    assert "delay: zero or a positive number of seconds; default 0.01. Transport delay to add." in Toy.__doc__
    with pytest.raises(PredictorError, match="toy: gain must be a positive number below 1, got 1.5"):
        Toy(gain=1.5)
    with pytest.raises(PredictorError, match="predictor 'toy' has no parameter gian; it takes: gain, delay"):
        Toy(gian=0.4)
