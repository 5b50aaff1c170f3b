"""The rig's own answer to "what is the latency?", from what a live run logged.

The rig knows what it showed and when: every image's pose (`published_poses.csv`) and the instant
its photons left the sphere's row (`display_frames.csv`: the measured swap plus the modelled
scan-out; for an external renderer, its swap markers, `renderer_markers.csv`), and what the tracker
measured and when (`tracker.csv`). The latency it implies is the one a perfect camera would
measure: the delay tau that best lines up the sphere's position as the display holds it with the
tracker's positions shifted by tau, along the swing's main axis (`rig.sim.truth.effective_latency`,
the definition the simulation's truth uses), over the whole run or over the instants a camera
filmed (which weights the run as the video does: frames a loaded camera dropped are missing from
both). Beside it, the mean and spread of the frame-by-frame sensor-to-photon delays.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np
from scipy.optimize import minimize_scalar

from predictors import read_samples
from rig.errors import RigError
from rig.live.files import MARKERS_FILE, PUBLISHED_FILE, read_columns, with_poses
from rig.session.run_files import DISPLAY_FRAMES_FILE, TRACKER_FILE
from rig.sim.truth import SCAN_STEP_S, effective_latency, shown_signal

# Left out at each end of the run: the predictor and the display settle, the last frames may be cut.
EDGE_S = 0.5


@dataclass(frozen=True)
class LogLatency:
    latency_ms: float
    delay_mean_ms: float
    delay_sd_ms: float
    frames: int
    period_s: float

    def to_dict(self) -> dict[str, Any]:
        return {"latency_ms": self.latency_ms, "sensor_to_photon_ms": {"mean": self.delay_mean_ms, "sd": self.delay_sd_ms},
                "frames": self.frames, "period_s": self.period_s}  # fmt: skip


def swing_period(t: np.ndarray, x: np.ndarray) -> float:
    """The swing's period (s) from the upward zero crossings of x about its mean."""
    centred = x - np.mean(x)
    up = np.flatnonzero((centred[:-1] < 0) & (centred[1:] >= 0))
    if len(up) < 3:
        raise RigError("the tracker saw fewer than three swings: a longer run, or release the pendulum before it starts")
    crossings = t[up] - centred[up] * (t[up + 1] - t[up]) / (centred[up + 1] - centred[up])
    return float(np.median(np.diff(crossings)))


def delay_at(instants: np.ndarray, switch: np.ndarray, drawn: np.ndarray, truth: Callable[[np.ndarray], np.ndarray],
             period_s: float, guess_s: float) -> float:  # fmt: skip
    """The delay tau (s) minimising the squared difference between the held signal (`drawn` from each
    `switch` time) and truth(t - tau), over the given instants only (those a camera filmed)."""
    held = shown_signal(switch, drawn, instants)
    t, held = instants[np.isfinite(held)], held[np.isfinite(held)]

    def cost(tau: float) -> float:
        return float(np.mean((held - truth(t - tau)) ** 2))

    taus = np.arange(guess_s - period_s / 2, guess_s + period_s / 2, SCAN_STEP_S)
    coarse = taus[int(np.argmin([cost(tau) for tau in taus]))]
    return float(minimize_scalar(cost, bounds=(coarse - SCAN_STEP_S, coarse + SCAN_STEP_S), method="bounded",
                                 options={"xatol": 1e-7}).x)  # fmt: skip


def log_latency(
    out_dir: Path, shown: dict[str, np.ndarray], scanout_s: np.ndarray | float = 0.0, instants: np.ndarray | None = None
) -> LogLatency:
    """The latency implied by a run's logs: `shown` has per shown image its switch time `t` (photons
    leave its row at t + scanout_s) and its pose's `px py pz` and `t_sensor`. With `instants` (the
    times a camera filmed), over those instants only: what that camera would have measured of the
    logged display, whatever it missed."""
    samples = read_samples(out_dir / TRACKER_FILE)
    if len(samples) < 10 or len(shown.get("t", ())) < 10:
        raise RigError(f"{out_dir} holds too few tracker samples or shown frames to work out the logged latency")
    t_sensor = np.array([s.t_sensor for s in samples])
    order = np.argsort(t_sensor, kind="stable")
    t_sensor = t_sensor[order]
    positions = np.array([s.position for s in samples])[order]
    keep = np.concatenate([[True], np.diff(t_sensor) > 0])
    t_sensor, positions = t_sensor[keep], positions[keep]
    centre = positions.mean(axis=0)
    axis = np.linalg.svd(positions - centre, full_matrices=False)[2][0]
    along = (positions - centre) @ axis
    switch = np.asarray(shown["t"]) + scanout_s
    drawn = (np.column_stack([shown["px"], shown["py"], shown["pz"]]) - centre) @ axis
    order = np.argsort(switch, kind="stable")
    switch, drawn, sensor = switch[order], drawn[order], np.asarray(shown["t_sensor"])[order]
    period = swing_period(t_sensor, along)
    span = (max(switch[0], t_sensor[0]) + EDGE_S, min(switch[-1], t_sensor[-1]) - EDGE_S)
    if span[1] - span[0] < 2 * period:
        raise RigError("the run is too short for the logged latency: it needs two swings after its first and last half second")
    delays = (switch - sensor)[(switch >= span[0]) & (switch <= span[1])]

    def truth(t: np.ndarray) -> np.ndarray:
        return np.interp(t, t_sensor, along)

    if instants is None:
        tau = effective_latency(switch, drawn, truth, span, period, float(np.mean(delays)))
    else:
        filmed = np.asarray(instants)[(instants >= span[0]) & (instants <= span[1])]
        if filmed.size < 10:
            raise RigError("the camera filmed too little of the logged run to compare the two")
        tau = delay_at(filmed, switch, drawn, truth, period, float(np.mean(delays)))
    return LogLatency(tau * 1e3, float(np.mean(delays)) * 1e3, float(np.std(delays)) * 1e3, int(len(delays)), period)


def shown_by_window(out_dir: Path) -> dict[str, np.ndarray]:
    """What the rig's own renderer showed: display_frames.csv joined with published_poses.csv."""
    frames, poses = read_columns(out_dir / DISPLAY_FRAMES_FILE), read_columns(out_dir / PUBLISHED_FILE)
    if not frames or not poses:
        return {}
    at, pose_at = with_poses(frames["image"], np.concatenate([[True], np.diff(frames["image"]) != 0]), poses)
    return {"t": frames["t_photon"][at], "t_sensor": frames["t_sensor_newest"][at],
            **{key: poses[key][pose_at] for key in ("px", "py", "pz")}}  # fmt: skip


def shown_by_markers(out_dir: Path) -> dict[str, np.ndarray]:
    """What an external renderer showed: its swap markers joined with the poses the rig published."""
    markers, poses = read_columns(out_dir / MARKERS_FILE), read_columns(out_dir / PUBLISHED_FILE)
    if not markers or not poses:
        return {}
    at, pose_at = with_poses(markers["frame"], np.concatenate([[True], np.diff(markers["frame"]) != 0]), poses)
    return {"t": markers["t_swap"][at], "t_sensor": poses["t_sensor"][pose_at],
            **{key: poses[key][pose_at] for key in ("px", "py", "pz")}}  # fmt: skip
