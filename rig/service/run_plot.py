"""A simulated run's truth drawn from its records: where the tracker put the sphere, where each
application frame predicted it and each refresh showed it, and the sensor-to-photon delay of
every refresh beside the run's true latency (`rig simulate --plot`)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from rig.report.figures import LEGEND_BESIDE
from rig.session.run_record import APP_FRAMES_FILE, DISPLAY_FRAMES_FILE, TRACKER_FILE


def _columns(path: Path, *names: str) -> list[np.ndarray]:
    with open(path, newline="", encoding="utf-8") as file:
        rows = list(csv.DictReader(file))
    return [np.array([float(row[name]) for row in rows]) for name in names]


def plot_run(out_dir: Path, latency_ms: float, path: Path) -> Path:
    """Draw the run in `out_dir` (its tracker, application and display frame records) into `path`."""
    t_sensor, tracker_x = _columns(out_dir / TRACKER_FILE, "t_sensor", "px")
    t_target, predicted_x = _columns(out_dir / APP_FRAMES_FILE, "t_photon_target", "x")
    t_photon, shown_x, delay_ms = _columns(out_dir / DISPLAY_FRAMES_FILE, "t_photon", "x", "delay_ms")
    figure = Figure(figsize=(10, 6), layout="constrained")
    pose, delay = figure.subplots(2, 1, sharex=True)
    pose.plot(t_sensor, tracker_x * 1e3, ".", markersize=2, label="tracker (at sensing)")
    pose.plot(t_target, predicted_x * 1e3, "-", linewidth=0.8, label="predicted (for its photon instant)")
    pose.step(t_photon, shown_x * 1e3, where="post", linewidth=0.8, label="displayed (at its photons)")
    pose.set_ylabel("sphere x (mm)")
    pose.legend(**LEGEND_BESIDE)
    delay.plot(t_photon, delay_ms, ".", markersize=2, label="newest sample to photons per refresh (what prediction hides)")
    delay.axhline(latency_ms, color="black", linewidth=1.0, label=f"true latency left after prediction {latency_ms:.2f} ms")
    delay.set_xlabel("time (s, rig clock)")
    delay.set_ylabel("delay (ms)")
    delay.legend(**LEGEND_BESIDE)
    figure.savefig(path)
    return path
