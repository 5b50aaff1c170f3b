"""Levenberg-Marquardt in numpy, for the fit's few parameters: algorithm 6.18 of Madsen and
Nielsen, "Introduction to Optimization and Data Fitting" (2010), as jaxopt's
``LevenbergMarquardt`` implements it with a materialised Jacobian, which the fit used before.

The damping starts at DAMPING_START times the largest diagonal element of J'J; an accepted step
(gain ratio rho > 0) multiplies it by max(1/3, 1 - (2 rho - 1)^3), a rejected one by nu, which
doubles after each rejection in a row (both capped at DAMPING_CAP). The iterations stop once a
step, accepted or not, is shorter than xtol (|x| - xtol), once the gradient is exactly zero, or
after ``max_iterations``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

DAMPING_START = 1e-6
DAMPING_CAP = 2.0**32


class Solution(NamedTuple):
    """The parameters where the iterations stopped, and how many there were."""

    params: np.ndarray
    iterations: int


def levenberg_marquardt(
    residual: Callable[[np.ndarray], np.ndarray],
    residual_and_jacobian: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
    params: np.ndarray,
    max_iterations: int,
    xtol: float,
) -> Solution:
    """Minimise |residual(x)|^2 from ``params``; ``residual_and_jacobian(x)`` gives both at x."""
    values, jacobian = residual_and_jacobian(params)
    normal, gradient = jacobian.T @ jacobian, jacobian.T @ values
    loss = 0.5 * float(values @ values)
    damping, increase = DAMPING_START * float(np.max(np.diag(normal))), 2.0
    iterations = 0
    while iterations < max_iterations:
        iterations += 1
        step = -np.linalg.solve(normal + damping * np.eye(params.size), gradient)
        trial = params + step
        trial_values = residual(trial)
        trial_loss = 0.5 * float(trial_values @ trial_values)
        gain_ratio = (loss - trial_loss) / (0.5 * float(step @ (damping * step - gradient)))
        if gain_ratio > 0:
            params, loss = trial, trial_loss
            values, jacobian = residual_and_jacobian(params)
            normal, gradient = jacobian.T @ jacobian, jacobian.T @ values
            damping *= max(1 / 3, 1 - (2 * gain_ratio - 1) ** 3)
            increase = 2.0
        else:
            damping = min(damping * increase, DAMPING_CAP)
            increase = min(2 * increase, DAMPING_CAP)
        if not (np.max(np.abs(gradient)) > 0 and np.linalg.norm(step) > xtol * (np.linalg.norm(params) - xtol)):
            break
    return Solution(params, iterations)
