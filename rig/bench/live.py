"""`rig bench live` (its command line declared in `rig.bench.live_settings`): what it measures.

1. **Sample arrival to pose**: the rig runs live (`rig.live.run`) for a while on an emulated LSL
   tracker at 1 kHz (`rig.live.selftest.emulator`) with the direct renderer in a window paced by a
   frame clock at 60 Hz under an X display; for every display frame, the time from the arrival of
   the newest sample behind its pose (`tracker.csv`, stamped by the reader thread) to the moment the
   renderer was handed the pose (`published_poses.csv`). It includes the wait for
   the next frame (a sample waits for the frame that uses it, up to a refresh); the frame's own
   share, from the frame's start (`app_frames.csv`) to its pose, is reported beside it.
2. **Swap to log**: a window paced the same way presents frames, and for each swap the time from
   the swap's return to its row being written and flushed to the swap log (`display_swaps.csv`).

Figures are medians, 95th percentiles and maxima in microseconds; the machine is shared, so compare
them within one run. A measurement that cannot be made (no X display, a run that timed nothing) is
its row failed with the reason, and the other is still made.
"""

from __future__ import annotations

import argparse
import csv
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from rig.bench.contract import Bench, Context, new_figure
from rig.clock import MonotonicClock
from rig.errors import RigError
from rig.devices.window import SWAP_COLUMNS, SwapRecord, WindowDisplay, WindowSettings
from rig.live.run import LiveConfig, run_live
from rig.live.selftest.emulator import EmulatedPendulum
from rig.live.selftest.frame_clock import FixedRateFrameClock
from rig.live.view import View
from rig.writers import CsvRecord
from rig.sim.layout import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

TRACKER_HZ = 1000.0
REFRESH_HZ = 60.0
SIZE = (160, 120)
SWAPS = 300
MEASURED = (("arrival_to_pose", "sample arrival to pose"), ("frame_start_to_pose", "  of which the frame's own"),
            ("swap_to_log", "swap to logged"))  # fmt: skip
"""Each figure of the report, and its row's label."""


def _column(path: Path, *names: str) -> list[np.ndarray]:
    with path.open(encoding="utf-8", newline="") as stream:
        rows = list(csv.DictReader(stream))
    return [np.array([float(row[name]) for row in rows]) for name in names]


def _figures(seconds: np.ndarray, what: str) -> dict[str, Any]:
    """The median, 95th percentile and maximum (us) of `what`; RigError where nothing was timed."""
    us = np.asarray(seconds) * 1e6
    if us.size == 0:
        raise RigError(f"nothing was timed: no {what} was recorded")
    return {"count": int(us.size), "median_us": float(np.median(us)), "p95_us": float(np.percentile(us, 95)), "max_us": float(us.max())}


def arrival_to_pose(out_dir: Path) -> dict[str, Any]:
    """From a live run's files: newest sample's arrival to pose, and the frame's own share."""
    t_sensor, t_arrival = _column(out_dir / "tracker.csv", "t_sensor", "t_arrival")
    frame, published, behind = _column(out_dir / "published_poses.csv", "frame", "t_pose", "t_sensor")
    index, start = _column(out_dir / "app_frames.csv", "index", "t_start")
    arrival_of = dict(zip(t_sensor.tolist(), t_arrival.tolist()))
    start_of = dict(zip(index.astype(int).tolist(), start.tolist()))
    waits = [p - arrival_of[s] for p, s in zip(published, behind) if s in arrival_of]
    own = [p - start_of[int(f)] for p, f in zip(published, frame) if int(f) in start_of]
    return {"arrival_to_pose": _figures(np.array(waits), "pose with its sample's arrival"),
            "frame_start_to_pose": _figures(np.array(own), "pose with its frame's start")}


def swap_to_log(out_dir: Path, swaps: int = SWAPS) -> dict[str, Any]:
    """A paced window's swaps, each timed from its return to its swap-log row flushed."""
    clock = MonotonicClock()
    delays: list[float] = []
    with CsvRecord(out_dir / "bench_swaps.csv", SWAP_COLUMNS, overwrite=True) as log:

        def write(swap: SwapRecord) -> None:
            log.write(swap)
            delays.append(clock.now() - swap.t_swap)

        display = WindowDisplay(WindowSettings(size=SIZE), frame_clock=FixedRateFrameClock(REFRESH_HZ), swap_log=write)
        display.connect(clock)
        try:
            image = np.zeros((SIZE[1], SIZE[0], 3), dtype=np.uint8)
            for k in range(swaps):
                display.present(image, clock.now(), k)
        finally:
            display.close()
    return {"swap_to_log": _figures(np.array(delays), "swap")}


def live_run(out_dir: Path, duration_s: float, context: Context) -> dict[str, Any]:
    """The live run's figures, arrival to pose and the frame's own share, and its health's verdict
    (`rig.live.health`: a stalled or hitching run's figures hold its stalls), its files in `out_dir`/run."""
    clock = MonotonicClock()
    pendulum = Pendulum(PendulumConfig(), t_end=duration_s + 30.0)
    layout = make_layout(pendulum, CameraConfig(), DisplayConfig(width=SIZE[0], height=SIZE[1]))
    name = f"RigBenchLive{os.getpid()}"
    context.log(f"live run: {duration_s:g} s, LSL tracker at {TRACKER_HZ:g} Hz, direct renderer, window at {REFRESH_HZ:g} Hz")
    emulator = EmulatedPendulum(name, duration_s + 30.0, clock, TRACKER_HZ)
    try:
        config = LiveConfig(tracker=f"lsl:{name}", renderer="direct", duration_s=duration_s, window=WindowSettings(size=SIZE),
                            streams=None)  # fmt: skip
        summary = run_live(config, out_dir / "run", view=View(layout.world_to_clip, layout.sphere_radius_m),
                           frame_clock=FixedRateFrameClock(REFRESH_HZ), clock=clock, overwrite=True)  # fmt: skip
    finally:
        emulator.close()
    return {**arrival_to_pose(out_dir / "run"), "run_health": summary["health"]["verdict"]}


def run(args: argparse.Namespace, context: Context) -> dict[str, Any]:
    """Both measurements (see the module docstring) after a live run of `args.duration` seconds, their
    files in the context's folder; one that cannot be made is `{"failed": reason}` in its place."""
    out_dir = context.folder
    report: dict[str, Any] = {}
    try:
        report.update(live_run(out_dir, args.duration, context))
    except RigError as error:
        context.log(f"live run failed: {error}")
        report.update({"arrival_to_pose": {"failed": str(error)}, "frame_start_to_pose": {"failed": str(error)}})
    context.log(f"swap to log: {SWAPS} swaps")
    load = os.getloadavg()[0]
    started = time.monotonic()
    try:
        report.update(swap_to_log(out_dir))
    except RigError as error:
        context.log(f"swap to log failed: {error}")
        report["swap_to_log"] = {"failed": str(error)}
    return {**report, "cpus": os.cpu_count(), "load_average_1min": load, "swap_bench_s": time.monotonic() - started}


def every_measurement_failed(report: dict[str, Any]) -> str | None:
    """A sentence where neither measurement could be made, else None."""
    if not all("failed" in report[key] for key, _ in MEASURED):
        return None
    live_failed, swaps_failed = report["arrival_to_pose"]["failed"], report["swap_to_log"]["failed"]
    if live_failed == swaps_failed:
        return f"every measurement failed: {live_failed}"
    return f"every measurement failed (the live run: {live_failed}; the swaps: {swaps_failed})"


def table(report: dict[str, Any]) -> str:
    lines = [f"{'what':<28}{'frames':>8}{'median us':>12}{'p95 us':>10}{'max us':>10}"]
    for key, label in MEASURED:
        f = report[key]
        if "failed" in f:
            lines.append(f"{label:<28}failed: {f['failed']}")
            continue
        lines.append(f"{label:<28}{f['count']:>8}{f['median_us']:>12.0f}{f['p95_us']:>10.0f}{f['max_us']:>10.0f}")
    if "run_health" in report:
        lines.append(f"the live run's health: {report['run_health']}")
    return "\n".join(lines)


def plot(report: dict[str, Any], path: Path) -> None:
    """Each figure's median, with a bar to its 95th percentile."""
    figure, axes = new_figure((6.0, 3.0))
    for i, (key, _) in enumerate(MEASURED):
        f = report[key]
        if "failed" in f:
            axes.annotate("failed (the table says why)", (0.5, i), xycoords=("axes fraction", "data"), ha="center", va="center")
        else:
            axes.errorbar([f["median_us"]], [i], xerr=[[0.0], [f["p95_us"] - f["median_us"]]], fmt="o", capsize=4)
    axes.set_yticks(range(len(MEASURED)), ["sample arrival to pose", "frame start to pose", "swap to logged"])
    axes.set_ylim(-0.5, len(MEASURED) - 0.5)
    if axes.has_data():
        axes.set_xscale("log")
    axes.set_xlabel("microseconds (median, bar to the 95th percentile)")
    figure.tight_layout()
    figure.savefig(path, dpi=120)


BENCH = Bench(
    run=run, table=table,
    notes=lambda report: f"machine noise: {report['cpus']} CPUs, 1-minute load average {report['load_average_1min']:.2f}",
    plot=plot, all_failed=every_measurement_failed,
)
