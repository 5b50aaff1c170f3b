"""predictors.make: predictors by name, with checked parameters; the package's public names."""

import math

import pytest

import predictors
from predictors import Predictor, PredictorError, make, names


def test_every_public_name_is_the_package_s_own():
    missing = [name for name in predictors.__all__ if not hasattr(predictors, name)]
    assert missing == []
    assert predictors.make is predictors.registry.make and predictors.PoseSample.__module__ == "predictors.pose"


def test_known_names():
    assert names() == ("hold", "slerp", "kalman-cv", "kalman-ca", "desp", "auto", "adaptive", "split", "rls")


def test_default_is_another_name_for_rls():
    assert predictors.DEFAULT == "default" and predictors.resolve("default") == "rls"
    assert predictors.resolve("slerp") == "slerp" and "default" not in names()
    assert type(make("default")) is type(make("rls"))
    assert make("default", memory=3.0).memory == 3.0


@pytest.mark.parametrize("name", names())
def test_make_returns_fresh_predictors(name):
    first, second = make(name), make(name)
    assert isinstance(first, Predictor)
    assert first is not second


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(PredictorError, match="unknown predictor 'kalman'; known predictors: hold, slerp, kalman-cv.*'default' is rls"):
        make("kalman")


def test_unknown_parameter_lists_the_accepted_ones():
    with pytest.raises(PredictorError, match="'slerp' has no parameter gain; it takes: min_interval"):
        make("slerp", gain=2.0)
    with pytest.raises(PredictorError, match="'hold' has no parameter min_interval; it takes: no parameters"):
        make("hold", min_interval=1e-3)


def test_parameters_reach_the_predictor():
    assert make("slerp", min_interval=0.004).min_interval == 0.004
    assert make("slerp").min_interval == 1e-6


@pytest.mark.parametrize("bad", [0.0, -1e-3, math.nan, math.inf, "fast", None])
def test_bad_min_interval_is_an_error(bad):
    with pytest.raises(PredictorError, match="min_interval must be"):
        make("slerp", min_interval=bad)


@pytest.mark.parametrize(
    ("name", "params", "message"),
    [
        ("kalman-cv", {"position_noise": 0.0}, "position_noise must be a positive number of metres"),
        ("kalman-ca", {"jerk_noise": -1.0}, "jerk_noise must be a positive number of m/s"),
        ("kalman-cv", {"max_gap": math.nan}, "max_gap must be a positive number of seconds"),
        ("desp", {"position_alpha": 1.0}, "position_alpha must be a positive number below 1"),
        ("desp", {"sample_interval": 0.0}, "sample_interval must be a positive number of seconds"),
        ("auto", {"margin": "wide"}, "margin must be a positive number"),
    ],
)
def test_bad_filter_parameters_name_the_parameter_and_unit(name, params, message):
    with pytest.raises(PredictorError, match=message):
        make(name, **params)
