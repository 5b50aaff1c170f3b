"""`rig measure --self-test`: the whole live measurement with stand-ins for the bench, under a
virtual X server (xvfb-run) or any X display.

An emulated LSL tracker (`rig.emulate`) streams the simulated pendulum; the rig runs live on the
monotonic clock with its renderer in a real window paced by a frame clock (`FixedRateFrameClock`),
or, with `external`, the example external renderer (`examples/external_renderer.py`) runs as a
separate process that speaks only LSL; the camera twin (`ScreenCamera`) films the window and the
emulator's LED; then the run is analysed as `rig measure` analyses one. The video's latency must
agree with the rig's own log's (`AGREEMENT_MS`): that is what the self-test checks, unless the run
was invalid (the rig stalled: `rig.live.health`), which the report then says instead.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

from analysis import AnalysisOptions
from rig.clock import MonotonicClock
from rig.devices.protocols import Display
from rig.devices.window import WindowDisplay, WindowSettings
from rig.errors import RigError
from rig.live.measure import MeasureReport, analyse_run, write_report
from rig.live.run import EXTERNAL, LiveConfig, run_live
from rig.live.selftest.emulator import EmulatedPendulum
from rig.live.selftest.frame_clock import FixedRateFrameClock
from rig.live.selftest.twin import ScreenCamera, TwinSetup
from rig.live.view import View
from rig.lsl import StreamNames
from rig.sim.layout import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

AGREEMENT_MS = 2.0
REFRESH_HZ = 60.0
CAMERA_FPS = 97.0
"""Incommensurate with the refresh (see rig.live.selftest.twin)."""
DISPLAY_SIZE = (160, 120)
"""Small: software OpenGL's per-pixel warp costs about a refresh at this size."""
CAMERA_SIZE = (480, 360)
WINDOW_POSITION = (0, 0)
EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "external_renderer.py"
# The emulator outlasts the run: connecting, framing and the end take their time.
EMULATOR_MARGIN_S = 30.0
EXAMPLE_LOG = "external_renderer.log"


def self_test(
    out_dir: Path,
    duration_s: float,
    *,
    renderer: str = "warp",
    external: bool = False,
    overwrite: bool = False,
    progress: Callable[[float, float], None] | None = None,
) -> MeasureReport:
    """Run the self-test into `out_dir` with the rig's `renderer` (or the external example) and
    analyse it; the report's video and log answers should agree within AGREEMENT_MS."""
    if not os.environ.get("DISPLAY"):
        raise RigError("the self-test needs an X display: run it under xvfb-run (Debian: xvfb), or on a desktop")
    clock = MonotonicClock()
    pendulum_end = duration_s + EMULATOR_MARGIN_S + 2.0
    pendulum = Pendulum(PendulumConfig(), t_end=pendulum_end)
    camera_config = CameraConfig(fps=CAMERA_FPS, width=CAMERA_SIZE[0], height=CAMERA_SIZE[1])
    layout = make_layout(pendulum, camera_config, DisplayConfig(width=DISPLAY_SIZE[0], height=DISPLAY_SIZE[1]))
    name = f"RigSelfTest{os.getpid()}"
    streams = StreamNames(pose=f"{name}Pose", tracker=f"{name}Tracker", markers=f"{name}Markers")
    config = LiveConfig(
        tracker=f"lsl:{name}",
        renderer=EXTERNAL if external else renderer,
        duration_s=duration_s,
        window=WindowSettings(size=DISPLAY_SIZE, position=WINDOW_POSITION, title="latency rig self-test"),
        streams=streams,
    )
    window_rect: list[tuple[int, int, int, int]] = [(*WINDOW_POSITION, *DISPLAY_SIZE)]

    def connected(display: Display) -> None:
        if isinstance(display, WindowDisplay) and display.window is not None:  # the rig's renderer draws in it
            window_rect[0] = display.window.rect

    emulator = EmulatedPendulum(name, duration_s + EMULATOR_MARGIN_S, clock)
    out_dir.mkdir(parents=True, exist_ok=True)
    renderer = _start_example(streams, out_dir) if external else None
    try:
        twin = TwinSetup(camera_config, layout, PendulumConfig(), pendulum_end, 1.0 / REFRESH_HZ, out_dir, seed=1)
        camera = ScreenCamera(twin, lambda: emulator.start, lambda: window_rect[0])
        run = run_live(config, out_dir, view=View(layout.world_to_clip, layout.sphere_radius_m),
                       frame_clock=FixedRateFrameClock(REFRESH_HZ), camera=camera, clock=clock, overwrite=overwrite,
                       progress=progress, on_connected=connected)  # fmt: skip
    finally:
        if renderer is not None:
            renderer.terminate()
            renderer.wait(timeout=10)
        emulator.close()
    film = run["film"]
    options = AnalysisOptions(led_roi=layout.led_roi, sphere_roi=layout.sphere_roi)
    report = analyse_run(out_dir, film["measured_fps"] if film else None, options, None, run)
    if not report.invalid:
        report.run["self_test"] = _agreement(report)
        write_report(report)
    return report


def _agreement(report: MeasureReport) -> dict[str, Any]:
    difference = report.video["latency_ms"] - report.log["latency_ms"]
    return {"difference_ms": difference, "tolerance_ms": AGREEMENT_MS, "agree": abs(difference) <= AGREEMENT_MS}


def _start_example(streams: StreamNames, out_dir: Path) -> subprocess.Popen:
    """The example renderer in a process of its own, its output in EXAMPLE_LOG."""
    if not EXAMPLE.is_file():
        raise RigError(f"the external-renderer example {EXAMPLE} is not here (it ships with the repository, not the wheel)")
    command = [sys.executable, str(EXAMPLE), "--pose", streams.pose, "--markers", streams.markers,
               "--size", "x".join(map(str, DISPLAY_SIZE)), "--position", ",".join(map(str, WINDOW_POSITION)),
               "--pace-hz", str(REFRESH_HZ)]  # fmt: skip
    with (out_dir / EXAMPLE_LOG).open("w", encoding="utf-8") as stream:
        return subprocess.Popen(command, stdout=stream, stderr=subprocess.STDOUT)

