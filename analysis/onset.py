"""When a blob starts and stops swinging: events that do not repeat every period.

A lab that starts filming and then releases the pendulum films the LED at rest, then swinging; the
sphere does the same ``latency`` later. The time between the two departures is the latency with
no whole-period ambiguity, good to a few frames, which is all that choosing among candidates a
period apart needs. Stopping the pendulum by hand gives the same at the end.

A blob departs when its distance from its resting place first exceeds DEPARTURE_FRACTION of the
farthest it gets from there (the far end of the first swing, twice the amplitude). Released from
rest, the distance grows as 1 - cos(omega t), so that threshold is crossed the same time after
the release for any amplitude in pixels: the LED's and the sphere's departures lie exactly the
latency apart, however large each appears. It must have rested first: over the clip's first MIN_REST_S
it stays within REST_FRACTION of that reach of its resting place (noise and a blinking LED's
missing frames allowed); a clip that starts mid-swing has no departure. The stop is the departure of the reversed track.
"""

from __future__ import annotations

import numpy as np

DEPARTURE_FRACTION = 0.05
REST_FRACTION = 0.01
MIN_REST_S = 0.2
# The reach is this percentile of the distances from rest: one stray detection does not set it.
REACH_PERCENTILE = 99.5
MIN_REST_FRAMES = 5


def departure_time(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> float | None:
    """The time (s) the point (x, y) leaves the place it rests at from the first sample, or None.

    t increasing; NaN positions are frames without the blob and are skipped. The time is
    interpolated between the last frame inside DEPARTURE_FRACTION of the reach and the first
    outside it.
    """
    valid = np.isfinite(x) & np.isfinite(y)
    t, x, y = t[valid], x[valid], y[valid]
    if t.size < 2 * MIN_REST_FRAMES:
        return None
    resting = t <= t[0] + MIN_REST_S
    if np.count_nonzero(resting) < MIN_REST_FRAMES:
        return None
    rest_x, rest_y = float(np.median(x[resting])), float(np.median(y[resting]))
    distance = np.hypot(x - rest_x, y - rest_y)
    reach = float(np.percentile(distance, REACH_PERCENTILE))
    if reach <= 0:
        return None
    away = np.flatnonzero(distance > DEPARTURE_FRACTION * reach)
    if away.size == 0 or away[0] == 0:
        return None
    first = int(away[0])
    if t[first - 1] - t[0] < MIN_REST_S or np.any(distance[resting] > REST_FRACTION * reach + _jitter(distance[resting])):
        return None
    before, after = distance[first - 1], distance[first]
    level = DEPARTURE_FRACTION * reach
    return float(t[first - 1] + (t[first] - t[first - 1]) * (level - before) / (after - before))


def _jitter(distance_at_rest: np.ndarray) -> float:
    """How far noise alone moves a resting blob: a generous bound from its spread at rest."""
    return 6.0 * float(np.median(distance_at_rest)) + 1e-9


def stop_time(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> float | None:
    """The time (s) the point comes to rest for the rest of the clip (the reversed departure), or None."""
    reversed_time = departure_time(-t[::-1], x[::-1], y[::-1])
    return None if reversed_time is None else -reversed_time
