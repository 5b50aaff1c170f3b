"""`measure`: a live run filmed by a camera, then three answers side by side (see `MeasureReport`).

1. the video's: the analyser (`rig.service.analyse`) on the camera's video, with its 95 % interval;
2. the rig's own log's: the latency its logged swaps and tracker samples imply (`rig.live.log_latency`),
   at the instants the camera filmed (so that both weight the run alike) and over the whole run,
   compared with the video's (`rig.live.video_vs_log`: a warning when the whole run's lies outside
   the video's interval; the comparison is added to the run's `live.json`);
3. with the rig board (`--board PORT`: it records beside the run into `board/`, an instrument of
   the session, `rig.board.instrument`), the photodiode's (`analysis.board.photodiode_latency`).

All three go into `measure.json` and `measure.png`, beside the run's files. The run's health
verdict (`rig.live.health`) comes first: a run that is invalid (the rig or its tracker stalled) is
not analysed, since its video would not show the system's latency; its report holds the verdict.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from analysis import AnalysisError, AnalysisOptions
from analysis.board.photodiode_latency import estimate_from_recording
from rig.board.instrument import BoardInstrument
from rig.devices.camera.opencv_camera import opencv_camera
from rig.errors import RigError
from rig.fresh_outputs import removed_unless_recorded
from rig.live.files import camera_instants
from rig.live.health import INVALID, VALID
from rig.live.log_latency import log_latency, shown_by_markers, shown_by_window
from rig.live.run import EXTERNAL, LiveConfig, run_live, write_summary
from rig.live.video_vs_log import video_against_log
from rig.live.view import View
from rig.render.protocol import RenderSetup
from rig.service.analyse import AnalysisRequest, analyse
from rig.session.run_files import BOARD_FOLDER, VIDEO_FILE

MEASURE_FILE = "measure.json"
PLOT_FILE = "measure.png"


@dataclass
class MeasureReport:
    """A measured run's answers; `video` and `log` are None where the run was invalid (not analysed)."""

    out_dir: Path
    video: dict[str, Any] | None
    log: dict[str, Any] | None
    board: dict[str, Any] | None
    run: dict[str, Any] = field(default_factory=dict)

    @property
    def health(self) -> dict[str, Any]:
        return self.run["health"]

    @property
    def invalid(self) -> bool:
        return self.health["status"] == INVALID

    def to_dict(self) -> dict[str, Any]:
        return {
            "verdict": self.health["verdict"],
            "latency_ms": self.video["latency_ms"] if self.video else None,
            "ci95_ms": self.video["ci95_ms"] if self.video else None,
            "log_latency_ms": self.log["latency_ms"] if self.log else None,
            "board_latency_ms": self.board["latency_ms"] if self.board else None,
            "video": self.video,
            "log": self.log,
            "board": self.board,
            "run": self.run,
            "out_dir": str(self.out_dir),
        }


def logged_latency(out_dir: Path, external: bool, run: dict[str, Any]) -> dict[str, Any]:
    """The log's answer for a run folder (`rig.live.log_latency`) at the instants the camera filmed,
    which weights the run as the video does, and over the whole run beside it."""
    scanout: np.ndarray | float = 0.0
    if external:
        shown = shown_by_markers(out_dir)
        view, display = run["view"], run["display"]
        setup = RenderSetup(1, 1, np.array(view["world_to_clip"]), view["sphere_radius_m"])
        rows = np.array([setup.row_fraction(p) for p in np.column_stack([shown["px"], shown["py"], shown["pz"]])])
        scanout = rows * display["scanout_fraction"] / display["refresh_hz"]
    else:
        shown = shown_by_window(out_dir)
    filmed = log_latency(out_dir, shown, scanout, camera_instants(out_dir, dropped=False)).to_dict()
    return {**filmed, "whole_run_latency_ms": log_latency(out_dir, shown, scanout).latency_ms}


def analyse_run(out_dir: Path, fps: float | None, options: AnalysisOptions, board: Path | None, run: dict[str, Any],
                progress: Callable[[int, int], object] | None = None) -> MeasureReport:  # fmt: skip
    """The three answers for a filmed live run in `out_dir` (its video analysed as `options` say, at
    the frame rate the camera measured); written to measure.json and measure.png. An invalid run
    (`run`'s health) is not analysed: its report holds the verdict only."""
    if run["health"]["status"] == INVALID:
        report = MeasureReport(out_dir, None, None, None, run)
        write_report(report)
        return report
    request = AnalysisRequest(out_dir / VIDEO_FILE, replace(options, fps=fps), tracks_csv=out_dir / "tracks.csv")
    try:
        video = analyse(request, progress).to_dict()
    except AnalysisError as error:
        if run["health"]["status"] == VALID:
            raise
        # The film's fault may be the rig's own: say so before the bench is changed for nothing.
        raise AnalysisError(
            f"{error}; but the run itself was {run['health']['verdict']}, which may be why: measure again with the "
            "machine less loaded before changing the bench"
        ) from None
    log = logged_latency(out_dir, run["renderer"] == EXTERNAL, run)
    run["video_vs_log"] = video_against_log(out_dir, video, log)
    write_summary(out_dir, run)
    board_result = None
    if board is not None:
        latency = estimate_from_recording(board)
        board_result = {"latency_ms": latency.latency_s * 1e3, "sd_ms": latency.uncertainty_s * 1e3, "folder": str(board)}
    report = MeasureReport(out_dir, video, log, board_result, run)
    write_report(report)
    plot_measurement(report, out_dir / PLOT_FILE)
    return report


def write_report(report: MeasureReport) -> Path:
    path = report.out_dir / MEASURE_FILE
    path.write_text(json.dumps(report.to_dict(), indent=1, default=str) + "\n", encoding="utf-8")
    return path


def plot_measurement(report: MeasureReport, path: Path) -> Path:
    """The answers side by side: each latency with its interval (the log's: the frame-by-frame
    sensor-to-photon spread)."""
    from matplotlib.figure import Figure

    rows = [("video", report.video["latency_ms"], report.video["ci95_ms"])]
    spread = report.log["sensor_to_photon_ms"]["sd"]
    rows.append(("rig log", report.log["latency_ms"], [report.log["latency_ms"] - spread, report.log["latency_ms"] + spread]))
    if report.board:
        value, sd = report.board["latency_ms"], report.board["sd_ms"]
        rows.append(("photodiode", value, [value - 1.96 * sd, value + 1.96 * sd]))
    figure = Figure(figsize=(6.0, 0.8 + 0.6 * len(rows)))
    axes = figure.subplots()
    for i, (name, value, interval) in enumerate(rows):
        low, high = interval if interval else (value, value)
        axes.errorbar([value], [i], xerr=[[value - low], [high - value]], fmt="o", capsize=4)
        axes.annotate(f"{value:.1f} ms", (value, i), textcoords="offset points", xytext=(0, 8), ha="center")
    axes.set_yticks(range(len(rows)), [name for name, _, _ in rows])
    axes.set_ylim(-0.7, len(rows) - 0.3)
    axes.set_xlabel("latency (ms): video 95 % interval, log +- 1 sd of frame delays, photodiode 95 %")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    return path


def measure(
    config: LiveConfig,
    camera_spec: str,
    out_dir: Path,
    *,
    view: View | None = None,
    options: AnalysisOptions = AnalysisOptions(),
    board_port: str | None = None,
    accept_camera_settings: bool = False,
    overwrite: bool = False,
    progress: Callable[[float, float], None] | None = None,
) -> MeasureReport:
    """Run `config` live while `camera_spec` films it and, given its port, the rig board records;
    then analyse (see the module docstring)."""
    camera = opencv_camera(camera_spec, accept_refused=accept_camera_settings)
    board = [BoardInstrument(board_port, out_dir / BOARD_FOLDER)] if board_port else []
    with removed_unless_recorded(out_dir):
        run = run_live(config, out_dir, view=view, camera=camera, instruments=board, overwrite=overwrite, progress=progress)
        film = run["film"]
        if run["health"]["status"] == INVALID:
            return analyse_run(out_dir, None, options, None, run)
        if film is None or film["frames"] < 2:
            raise RigError(f"the camera {camera_spec} recorded no video; check it films while the run goes")
    return analyse_run(out_dir, film["measured_fps"], options, out_dir / BOARD_FOLDER if board else None, run)
