"""Writing what an analysis found to files people and spreadsheets read."""

from __future__ import annotations

import csv
import math
from pathlib import Path

from analysis.result import LatencyResult

TRACKS_CSV_HEADER = ("t", "led_x", "led_y", "led_valid", "sphere_x", "sphere_y", "sphere_valid")


def _number(value: float) -> str:
    """A coordinate for CSV; empty where there was no blob (NaN)."""
    return "" if math.isnan(value) else f"{value:.4f}"


def write_tracks_csv(path: str | Path, result: LatencyResult) -> None:
    """Write both tracks, one row per frame: time in s, positions in px, validity as 0/1."""
    led, sphere = result.led_track, result.sphere_track
    with Path(path).open("w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(TRACKS_CSV_HEADER)
        for i, t in enumerate(led.t):
            writer.writerow(
                (
                    f"{t:.6f}",
                    _number(led.x[i]),
                    _number(led.y[i]),
                    int(led.valid[i]),
                    _number(sphere.x[i]),
                    _number(sphere.y[i]),
                    int(sphere.valid[i]),
                )
            )
