"""Live runs end to end on the real clock, under a virtual X server: `rig measure --self-test` with
the rig's warp renderer and with the external-renderer example speaking only LSL (a valid run's
video latency must agree with the rig's own log within 2 ms, nothing is lost, and the exit status
says the run's health verdict; an invalid run names the stall), a tracker unplugged mid-run, and the
one-line errors of a missing display or camera. Only what holds on a slow shared machine is
asserted: the verdict and the exit status agree, agreement between two measurements of a valid run,
and counts."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from rig.cli import EXIT_UNTRUSTED, EXIT_WARNINGS
from rig.devices.window import WindowSettings
from rig.emulate import EmulatorConfig, make_sink, quiet_tracker, run_emulator
from rig.errors import RigError
from rig.live.run import LiveConfig, run_live
from rig.live.selftest.frame_clock import FixedRateFrameClock
from rig.live.view import View
from rig.sim.layout import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.writers import VideoRecord

RIG = [sys.executable, "-m", "rig.cli"]
SELF_TEST_S = 12.0
AGREEMENT_MS = 2.0


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as stream:
        return list(csv.DictReader(stream))


def _expected_exit(report: dict) -> int:
    """The exit status `rig measure` documents for this report: an invalid run 4, a self-test's
    disagreement 1, a degraded run or a video that misses the whole run 3, else 0."""
    run = report["run"]
    if run["health"]["status"] == "invalid":
        return EXIT_UNTRUSTED
    if not run["self_test"]["agree"]:
        return 1
    return EXIT_WARNINGS if run["health"]["status"] == "degraded" or run["video_vs_log"]["warning"] else 0


def _self_test(out: Path, *extra: str) -> dict:
    """The self-test's report, its exit status checked against its verdict."""
    done = subprocess.run([*RIG, "measure", "--self-test", "--json", "--duration", str(SELF_TEST_S), "--out", str(out), *extra],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.stdout, done.stderr
    report = json.loads(done.stdout)
    assert done.returncode == _expected_exit(report), done.stderr
    assert json.loads((out / "live.json").read_text())["health"]["verdict"] == report["verdict"]
    return report


def _nothing_lost(out: Path, report: dict) -> None:
    run = report["run"]
    assert len(_rows(out / "tracker.csv")) == run["tracker_report"]["counters"]["received"] > 0
    assert run["film"]["frames"] > 0.5 * SELF_TEST_S * run["film"]["fps"]
    assert run["film"]["frames"] == len(_rows(out / "camera_frames.csv"))
    assert run["ended"] == "completed"


@pytest.mark.parametrize("renderer", ["warp", "external"])
def test_the_self_test_video_agrees_with_the_rigs_own_log(tmp_path: Path, x_display: str, renderer: str) -> None:
    report = _self_test(tmp_path, *(["--external"] if renderer == "external" else []))
    if report["run"]["health"]["status"] == "invalid":
        assert "stalled" in report["verdict"] and report["latency_ms"] is None
        return
    assert {"latency_ms", "ci95_ms", "log_latency_ms"} <= report.keys()
    if report["run"]["health"]["status"] == "valid":
        assert abs(report["latency_ms"] - report["log_latency_ms"]) <= AGREEMENT_MS
    assert report["ci95_ms"][0] <= report["latency_ms"] <= report["ci95_ms"][1]
    _nothing_lost(tmp_path, report)
    poses = {row["frame"] for row in _rows(tmp_path / "published_poses.csv")}
    if renderer == "warp":
        swaps = _rows(tmp_path / "display_swaps.csv")
        assert len(swaps) == report["run"]["display"]["swaps"] and {row["image"] for row in swaps} <= poses
    else:
        drawn = {row["frame"] for row in _rows(tmp_path / "renderer_markers.csv")} - {"-1.0", "-1"}
        assert drawn and drawn <= poses


def test_a_tracker_unplugged_mid_run_ends_it_cleanly_with_everything_kept(tmp_path: Path, x_display: str) -> None:
    emulator = EmulatorConfig("pty", str(tmp_path / "tracker"), quiet_tracker(400.0), 3.0, "binary-pose")
    sink = make_sink(emulator)
    sent = {}

    def stream_then_unplug() -> None:
        sent["counts"] = run_emulator(emulator, sink, lambda message: None)
        sink.close()

    thread = threading.Thread(target=stream_then_unplug)
    thread.start()
    pendulum = Pendulum(PendulumConfig(), t_end=10.0)
    layout = make_layout(pendulum, CameraConfig(), DisplayConfig(width=160, height=120))
    config = LiveConfig(tracker=f"serial:{sink.address}?profile=binary-pose", renderer="direct", duration_s=60.0,
                        window=WindowSettings(size=(160, 120)), streams=None)  # fmt: skip
    try:
        with pytest.raises(RigError, match="was lost"):
            run_live(config, tmp_path / "run", view=View(layout.world_to_clip, layout.sphere_radius_m),
                     frame_clock=FixedRateFrameClock(60.0))  # fmt: skip
    finally:
        thread.join()
    live = json.loads((tmp_path / "run" / "live.json").read_text())
    assert "was lost" in live["ended"]
    assert len(_rows(tmp_path / "run" / "tracker.csv")) == sent["counts"].intact
    assert len(_rows(tmp_path / "run" / "display_frames.csv")) > 0


def test_no_display_is_one_line_and_exit_2(tmp_path: Path) -> None:
    environment = {key: value for key, value in os.environ.items() if key != "DISPLAY"}
    done = subprocess.run([*RIG, "measure", "--self-test"], capture_output=True, text=True, env=environment, timeout=120)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "X display" in done.stderr


def test_rig_record_films_a_file_camera_and_a_missing_camera_is_one_line(tmp_path: Path) -> None:
    with VideoRecord(tmp_path / "in.avi", 30.0, 64, 48) as video:
        for _ in range(30):
            video.write(np.zeros((48, 64), dtype=np.uint8))
    done = subprocess.run([*RIG, "record", "--camera", f"camera:{tmp_path / 'in.avi'}", "--duration", "5", "--out",
                           str(tmp_path / "out"), "--json"], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["frames"] == 30
    missing = subprocess.run([*RIG, "record", "--camera", "camera:7", "--duration", "1", "--out", str(tmp_path / "none")],
                             capture_output=True, text=True, timeout=120)  # fmt: skip
    assert missing.returncode == 2 and len(missing.stderr.strip().splitlines()) == 1
