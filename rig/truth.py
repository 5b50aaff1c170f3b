"""The true effective latency of a simulated run: what an ideal video analyser would measure.

The display emits a step function: the sphere's x stays where a refresh drew it until the next
refresh reaches the sphere's row. The effective latency is the delay tau minimising

    J(tau) = integral over the filmed span of (x_shown(t) - x_led(t - tau))^2 dt,

found by a scan over one pendulum period around a guess (the mean sensor-to-photon delay), using
the LED signal tabulated once and interpolated, then refined with a bounded scalar minimiser that
evaluates the LED exactly.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from scipy.optimize import minimize_scalar

GRID_STEP_S = 1e-4
SCAN_STEP_S = 1e-3


def shown_signal(switch_times: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Sample-and-hold: values[i] from switch_times[i] until the next switch; NaN before the first."""
    index = np.searchsorted(switch_times, t, side="right") - 1
    return np.where(index >= 0, values[np.maximum(index, 0)], np.nan)


def effective_latency(
    switch_times: np.ndarray,
    x_shown: np.ndarray,
    led_x: Callable[[np.ndarray], np.ndarray],
    span: tuple[float, float],
    period_s: float,
    guess_s: float = 0.0,
) -> float:
    """The delay tau (s) minimising the squared difference between x_shown(t) and led_x(t - tau)."""
    # Midpoints of a fine grid: no instant falls exactly on a switch, so the integral of the
    # step function is unbiased wherever the switches lie.
    t = np.arange(span[0], span[1], GRID_STEP_S) + GRID_STEP_S / 2
    shown = shown_signal(switch_times, x_shown, t)
    valid = np.isfinite(shown)
    t, shown = t[valid], shown[valid]

    def cost(tau: float) -> float:
        return float(np.mean((shown - led_x(t - tau)) ** 2))

    taus = np.arange(guess_s - period_s / 2, guess_s + period_s / 2, SCAN_STEP_S)
    table_t = np.arange(t[0] - taus[-1] - SCAN_STEP_S, t[-1] - taus[0] + SCAN_STEP_S, GRID_STEP_S)
    table_x = led_x(table_t)

    def coarse_cost(tau: float) -> float:
        return float(np.mean((shown - np.interp(t - tau, table_t, table_x)) ** 2))

    coarse = taus[int(np.argmin([coarse_cost(tau) for tau in taus]))]
    fine = minimize_scalar(cost, bounds=(coarse - SCAN_STEP_S, coarse + SCAN_STEP_S), method="bounded", options={"xatol": 1e-7})
    return float(fine.x)
