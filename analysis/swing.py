"""The free swing both blobs make: when it is free, what happens once in it, its frequency, damping and phases.

Estimation starts here (``analysis.estimation``): both tracks are cut to the span in which both
blobs swing freely, from the later departure from rest to the earlier stop less STOP_MARGIN_S (a
hand slowing the pendulum is no free swing), and reduced to signals along their main axes
(``analysis.signals``). Their frequency, the LED's damping and the per-period phases
(``analysis.windows``) are measured once here and shared by cycle resolution and every estimator.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from analysis.onset import departure_time, stop_time
from analysis.phase import estimate_frequency
from analysis.signals import SwingSignals, swing_signals
from analysis.blobs import Track
from analysis.windows import WindowPhases, damping_rate, window_phases

# The swing is analysed up to this long before the first blob stops (a hand slowing the pendulum
# is no free swing).
STOP_MARGIN_S = 0.2


@dataclass(frozen=True)
class Swing:
    """The free swing, measured.

    signals: both signals during the free swing; uniform: (t, led, sphere) on a uniform grid at
    ``fps``, gaps interpolated; frequency_hz from the LED; damping (1/s) from the LED's amplitudes
    per period; windows: both signals' phases per period; events_s: the sphere-minus-LED lags (s)
    of the swing's one-off events (``analysis.cycles``); span_s: [start, end] of the free swing (s).
    """

    signals: SwingSignals
    uniform: tuple[np.ndarray, np.ndarray, np.ndarray]
    fps: float
    frequency_hz: float
    damping: float
    windows: WindowPhases
    events_s: dict[str, float]
    span_s: tuple[float, float]

    @property
    def period_s(self) -> float:
        return 1.0 / self.frequency_hz


def _swing_events(
    led: Track, sphere: Track, reference_departures: Mapping[str, float]
) -> tuple[dict[str, float], tuple[float, float]]:
    """Sphere-minus-LED lags of the swing's one-off events (``analysis.cycles``), and the span in
    which both blobs swing freely: from the later departure to the earlier stop less STOP_MARGIN_S."""
    departures = (departure_time(led.t, led.x, led.y), departure_time(sphere.t, sphere.x, sphere.y))
    stops = (stop_time(led.t, led.x, led.y), stop_time(sphere.t, sphere.x, sphere.y))
    events: dict[str, float] = {}
    if departures[1] is not None:
        if departures[0] is not None:
            events["swing start"] = departures[1] - departures[0]
        for name, time in reference_departures.items():
            events[name] = departures[1] - time
    if stops[0] is not None and stops[1] is not None:
        events["swing stop"] = stops[1] - stops[0]
    begin = max((d for d in departures if d is not None), default=-math.inf)
    end = min((s - STOP_MARGIN_S for s in stops if s is not None), default=math.inf)
    return events, (max(begin, float(led.t[0])), min(end, float(led.t[-1])))


def during(track: Track, span: tuple[float, float], clock: np.ndarray | None = None) -> Track:
    """The frames of a track whose times lie inside [start, end]: its own times, or ``clock``'s (the
    LED's, so that the sphere, dated by other rows, keeps the same frames)."""
    times = track.t if clock is None else clock
    inside = (times >= span[0]) & (times <= span[1])
    columns = {column.name: getattr(track, column.name) for column in dataclasses.fields(Track)}
    return Track(**{name: values[inside] if values is not None else None for name, values in columns.items()})


def measure_swing(led: Track, sphere: Track, reference_departures: Mapping[str, float]) -> Swing:
    """The free swing in both tracks. ``reference_departures`` names times (s, on the tracks' clock)
    at which other instruments saw the pendulum depart from rest; each, with the sphere's own
    departure, is one more event lag."""
    events, span = _swing_events(led, sphere, reference_departures)
    signals = swing_signals(during(led, span), during(sphere, span, led.t))
    uniform = signals.uniform()
    fps = 1.0 / signals.frame_interval
    frequency = estimate_frequency(uniform[1], fps)
    damping = damping_rate(window_phases(signals, frequency))
    windows = window_phases(signals, frequency, damping)
    return Swing(signals, uniform, fps, frequency, damping, windows, events, span)
