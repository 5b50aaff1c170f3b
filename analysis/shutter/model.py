"""What a camera row records of a flashing light, and which exposures a film cannot tell apart.

A light flashing at f Hz is on for the first `duty` of each period: on at time t when
frac(f t - psi) < duty. Row y of frame k exposes from t_k + y L to t_k + y L + E (a rolling shutter
reads row y y L after row 0; a global shutter has L = 0). In cycles of the flash, the row's
exposure starts at u = f (t_k + y L) - psi and lasts e = E f, and the share of it the light was on
is ``on_fraction(u, e, duty)``: the square wave averaged over a window of e cycles, a trapezoid with
plateaus at 1 and 0 and ramps e cycles long while e < min(duty, 1 - duty).

That trapezoid is the square wave convolved with the exposure's box, and convolution does not
say which box was which: once each row is normalised by its own on and off levels, the same film
comes from three other (exposure, duty) pairs (``other_readings``). Only what the lab knows (the
light's duty cycle, the longest exposure the camera can have) rules them out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def on_fraction(u: np.ndarray, exposure: float, duty: float) -> np.ndarray:
    """The share of each window [u, u + exposure] (cycles of the flash) during which a light, on
    for [n, n + duty) of every cycle n, was on. Exact for any exposure > 0."""

    def lit(v: np.ndarray) -> np.ndarray:  # time on from 0 to v, in cycles
        whole = np.floor(v)
        return whole * duty + np.minimum(v - whole, duty)

    return (lit(u + exposure) - lit(u)) / exposure


def on_fraction_derivatives(u: np.ndarray, exposure: float, duty: float, fraction: np.ndarray) -> np.ndarray:
    """The derivatives of ``on_fraction`` (whose values at u are ``fraction``) in u, exposure and
    duty, stacked (3, *u.shape); at a kink, the one on the side of larger arguments."""

    def on(v: np.ndarray) -> np.ndarray:
        return ((v - np.floor(v)) < duty).astype(np.float64)

    def lit_by_duty(v: np.ndarray) -> np.ndarray:
        whole = np.floor(v)
        return whole + ((v - whole) >= duty)

    end = u + exposure
    on_at_end = on(end)
    return np.stack([(on_at_end - on(u)) / exposure, (on_at_end - fraction) / exposure, (lit_by_duty(end) - lit_by_duty(u)) / exposure])


LONGER_THAN_BOTH = "exposure longer than the on and off times"


@dataclass(frozen=True)
class Reading:
    """One way to read a film's trapezoid: an exposure and a duty cycle, both in cycles of the
    flash, and how (``which``: "ramps" when the ramps are the exposure, the only reading in which
    the ramps do not meet)."""

    which: str
    exposure: float
    duty: float


def other_readings(exposure: float, duty: float) -> tuple[Reading, ...]:
    """The readings of a trapezoid fitted as (exposure, duty), with exposure < min(duty, 1 - duty),
    that give the same normalised rows: the exposure and the duty swapped (the exposure longer
    than the on time), the exposure as long as the off time, and the exposure one period less the
    fitted one (longer than both the on and the off time)."""
    return (
        Reading("exposure as long as the on time", duty, exposure),
        Reading("exposure as long as the off time", 1.0 - duty, 1.0 - exposure),
        Reading(LONGER_THAN_BOTH, 1.0 - exposure, 1.0 - duty),
    )
