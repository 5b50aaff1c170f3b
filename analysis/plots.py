"""Pictures of an analysis for people: the two tracks, and how well the measured delay lines them up."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from analysis.phase import axis_signal
from analysis.result import LatencyResult

SHOWN_SECONDS = 3.0


def plot_tracks(result: LatencyResult, path: str | Path, title: str | None = None) -> Path:
    """Write a PNG: both tracks along their swing axes, then the LED delayed by the measured latency.

    Each signal is scaled to unit amplitude, so the sphere's lag is visible whatever the two
    image scales are; the lower panel shows what is left once the latency is taken out.
    """
    led = axis_signal(result.led_track, "LED")
    sphere = axis_signal(result.sphere_track, "sphere")
    t = result.led_track.t
    led, sphere = led / np.abs(led).max(), sphere / np.abs(sphere).max()
    shown = t <= t[0] + SHOWN_SECONDS
    delay = result.latency_ms / 1e3

    figure = Figure(figsize=(9, 6))
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t[shown], led[shown], label="LED (real)")
    top.plot(t[shown], sphere[shown], label="sphere (rendered)")
    top.set_ylabel("swing (normalised)")
    top.legend(loc="upper right")
    delayed_led = np.interp(t, t + delay, led)
    bottom.plot(t[shown], delayed_led[shown], label=f"LED delayed by {result.latency_ms:.2f} ms")
    bottom.plot(t[shown], sphere[shown], "--", label="sphere")
    bottom.set_xlabel("time in video (s)")
    bottom.set_ylabel("swing (normalised)")
    bottom.legend(loc="upper right")
    figure.suptitle(title or f"latency {result.latency_ms:.2f} ms ({result.method})")
    figure.tight_layout()
    path = Path(path)
    figure.savefig(path, dpi=100)
    return path
