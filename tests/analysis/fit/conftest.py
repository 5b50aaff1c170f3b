"""Swing signals of known latency for the fit's tests, given to them as the ``swing`` fixture, and
jaxopt's solver as the fit was configured before it moved to numpy, the reference it is checked
against (``jaxopt_levenberg_marquardt``)."""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from analysis.cycles import chirp_shape
from analysis.fit import model
from analysis.fit.least_squares import STEP_TOLERANCE, Guess
from analysis.signals import SwingSignals


def make_swing(
    latency: float,
    *,
    period: float = 0.8,
    seconds: float = 6.0,
    fps: float = 120.0,
    decay: float = 0.0,
    chirp: float = 0.0,
    wide: float = 0.0,
    drift: float = 0.0,
    noise: tuple[float, float] = (0.0, 0.0),
    seed: int = 0,
) -> tuple[SwingSignals, Guess]:
    """LED and sphere signals of a swing decaying at ``decay`` (1/s) whose frequency rises as it
    decays (``chirp``, zeta in rad/s^2, see analysis.fit.model), with a third harmonic of relative
    size ``wide`` and a quadratic drift of the sphere of ``drift`` px at the clip's ends; the sphere
    shows the swing ``latency`` s later. With them, a starting guess a little off the truth."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fps)) / fps

    def position(time: np.ndarray) -> np.ndarray:
        phase = 2 * math.pi * time / period - chirp * chirp_shape(time - seconds / 2, decay) + 0.3
        return np.exp(-decay * time) * (np.sin(phase) - wide * np.exp(-2 * decay * time) * np.sin(3 * phase))

    led = 40 * position(t) + noise[0] * rng.standard_normal(t.size)
    bend = drift * ((t - seconds / 2) / (seconds / 2)) ** 2
    sphere = 25 * position(t - latency) + 3.0 + bend + noise[1] * rng.standard_normal(t.size)
    guess = Guess(1 / period * 1.0005, decay, 0.0, latency + 0.004, 0.6)
    return SwingSignals(t, led, sphere), guess


@pytest.fixture
def swing() -> Callable[..., tuple[SwingSignals, Guess]]:
    return make_swing


@functools.cache
def jaxopt_levenberg_marquardt(max_iterations: int) -> Any:
    """jaxopt's Levenberg-Marquardt on the projected residual, configured as the JAX fit had it
    (one solver per iteration limit, so what a test compiles of it is compiled once)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="JAXopt is no longer maintained", category=DeprecationWarning)
        import jaxopt

    return jaxopt.LevenbergMarquardt(
        residual_fun=model.projected_residual,
        maxiter=max_iterations,
        stop_criterion="madsen-nielsen",
        xtol=STEP_TOLERANCE,
        gtol=0.0,
        solver="cholesky",
        materialize_jac=True,
        implicit_diff=False,
    )


@pytest.fixture
def jaxopt_solver() -> Callable[[int], Any]:
    return jaxopt_levenberg_marquardt
