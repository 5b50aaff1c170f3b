"""When a blob starts and stops swinging: events that do not repeat every period.

A lab that starts filming and then releases the pendulum films the LED at rest, then swinging; the
sphere does the same ``latency`` later. The time between the two departures is the latency with
no whole-period ambiguity, good to a few frames, which is all that choosing among candidates a
period apart needs. Stopping the pendulum by hand gives the same at the end.

A blob departs when its distance from its resting place first exceeds DEPARTURE_FRACTION of the
farthest it gets from there (the far end of the first swing, twice the amplitude). Released from
rest, the distance grows as 1 - cos(omega t), so that threshold is crossed the same time after
the release for any amplitude in pixels: the LED's and the sphere's departures lie exactly the
latency apart, however large each appears. A blob that jitters at rest (a rendered sphere follows
the tracker's noise) departs only beyond its jitter, and only when CONFIRM_FRAMES frames in a row
are beyond the level. It must have rested first: over the clip's first MIN_REST_S it stays within
REST_FRACTION of that reach, plus its jitter, of its resting place (a blinking LED's missing frames
are skipped); a clip that starts mid-swing has no departure. The stop is the departure of the reversed track.
"""

from __future__ import annotations

import numpy as np

DEPARTURE_FRACTION = 0.05
REST_FRACTION = 0.01
MIN_REST_S = 0.2
# The reach is this percentile of the distances from rest: one stray detection does not set it.
REACH_PERCENTILE = 99.5
MIN_REST_FRAMES = 5
# Noise moves a resting blob at most this many standard deviations from its resting place...
JITTER_FACTOR = 6.0
MAD_TO_SIGMA = 1.4826
# ...and a departure is this many frames in a row beyond the level (one stray detection is none).
CONFIRM_FRAMES = 3


def departure_time(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> float | None:
    """The time (s) the point (x, y) leaves the place it rests at from the first sample, or None.

    t increasing; NaN positions are frames without the blob and are skipped. The time is
    interpolated between the last frame inside the departure level and the first beyond it.
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
    jitter = JITTER_FACTOR * max(_noise_sd(x[resting]), _noise_sd(y[resting]))
    if np.any(distance[resting] > REST_FRACTION * reach + jitter):
        return None
    level = max(DEPARTURE_FRACTION * reach, jitter)
    held = np.convolve(distance > level, np.ones(CONFIRM_FRAMES), "valid") == CONFIRM_FRAMES
    away = np.flatnonzero(held)
    if away.size == 0 or away[0] == 0 or t[away[0] - 1] - t[0] < MIN_REST_S:
        return None
    first = int(away[0])
    before, after = distance[first - 1], distance[first]
    return float(t[first - 1] + (t[first] - t[first - 1]) * (level - before) / (after - before))


def _noise_sd(values: np.ndarray) -> float:
    """The standard deviation of white noise on a smooth signal, from its second differences
    (which a swing, sampled many times per period, hardly has): robust, so a swing that has
    started does not pass for noise."""
    second = np.diff(values, 2)
    if second.size == 0:
        return 0.0
    return MAD_TO_SIGMA * float(np.median(np.abs(second - np.median(second)))) / np.sqrt(6.0)


def stop_time(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> float | None:
    """The time (s) the point comes to rest for the rest of the clip (the reversed departure), or None."""
    reversed_time = departure_time(-t[::-1], x[::-1], y[::-1])
    return None if reversed_time is None else -reversed_time
