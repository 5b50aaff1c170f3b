"""`rig check` under a virtual X server with the stand-ins: an emulated tracker (over a pty, and over
socket:// from the command line), a file camera, and the window paced by the injected frame clock as
the self-test paces it (a virtual X server does not pace swaps: unpaced, the display check fails, as
it must on a monitor with vsync off). Real time: only what holds on a slow shared machine is
asserted: rates measured against the stand-ins' own, statuses, and the time taken only loosely."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from pathlib import Path
from typing import Iterator

import numpy as np
import pytest

from rig.emulate import EmulatorConfig, make_sink, quiet_tracker, run_emulator
from rig.live.selftest.frame_clock import FixedRateFrameClock
from rig.preflight import LISTEN_S, CheckPlan, run_checks
from rig.preflight.rows import FAIL, PASS, WARN
from rig.writers import VideoRecord

RIG = [sys.executable, "-m", "rig.cli"]
TRACKER_HZ = 400.0
CAMERA_FPS = 30.0
CHECK_LIMIT_S = 15.0
"""What a check should take; asserted only four times over (the machine may be slow), reported."""
LOAD_DEPENDENT = {("tracker", "jitter"), ("display", "swaps paced"), ("display", "refresh")}
"""Checks that a loaded machine may turn to a warning on its own."""


@pytest.fixture
def film(tmp_path: Path) -> Path:
    """A camera's recording to play as the camera: 6 s at CAMERA_FPS, a bright spot moving."""
    path = tmp_path / "camera.avi"
    with VideoRecord(path, CAMERA_FPS, 160, 120) as video:
        for i in range(int(6 * CAMERA_FPS)):
            frame = np.zeros((120, 160), dtype=np.uint8)
            frame[50:60, 10 + i % 140 : 20 + i % 140] = 255
            video.write(frame)
    return path


@pytest.fixture
def pty_tracker(tmp_path: Path) -> Iterator[str]:
    """An emulated tracker on a pty, streaming once read (it ends when its reader hangs up); its spec."""
    config = EmulatorConfig("pty", str(tmp_path / "tracker"), quiet_tracker(TRACKER_HZ), 20.0)
    sink = make_sink(config)
    ready = threading.Event()
    thread = threading.Thread(target=run_emulator, args=(config, sink, lambda message: None), kwargs={"on_ready": ready.set})
    thread.start()
    assert ready.wait(timeout=60), "the emulator did not work out its samples"
    yield f"serial:{sink.address}"
    thread.join(timeout=120)
    sink.close()


def _by_check(rows: list) -> dict[tuple[str, str], object]:
    return {(row.device, row.what): row for row in rows}


def test_a_check_of_the_stand_ins_measures_each_at_its_own_rate(tmp_path: Path, x_display: str, film: Path, pty_tracker: str) -> None:
    plan = CheckPlan(tracker=pty_tracker, camera=f"camera:{film}", display="window?size=160x120", duration_s=60.0, disk_folder=tmp_path)
    report = run_checks(plan, frame_clock=FixedRateFrameClock(60.0))
    rows = _by_check(report.rows)
    assert set(rows) == {("display", "refresh"), ("display", "swaps paced"), ("tracker", "rate"), ("tracker", "jitter"),
                         ("tracker", "clock offset"), ("camera", "settings"), ("camera", "frame rate"), ("camera", "exposure"),
                         ("disk", "room for the film")}  # fmt: skip
    assert rows["display", "refresh"].values["refresh_hz"] == pytest.approx(60.0, rel=0.02)
    assert rows["display", "refresh"].values["timing_source"] == "frame-clock"
    assert rows["tracker", "rate"].values["rate_hz"] == pytest.approx(TRACKER_HZ, rel=0.01)
    assert rows["camera", "frame rate"].values["delivered_fps"] == pytest.approx(CAMERA_FPS, rel=0.01)
    for key, row in rows.items():
        assert row.status == PASS or (row.status == WARN and key in LOAD_DEPENDENT), (key, row)
    assert rows["disk", "room for the film"].values["needed_bytes"] > 0
    assert LISTEN_S <= report.seconds < 4 * CHECK_LIMIT_S


def test_the_command_fails_an_unpaced_window_and_checks_the_rest_as_json(tmp_path: Path, x_display: str, film: Path) -> None:
    emulator = subprocess.Popen([*RIG, "emulate-tracker", "serial", "--tcp", "0", "--rate", str(TRACKER_HZ), "--duration", "60",
                                 "--idle-timeout", "60"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)  # fmt: skip
    try:
        spec = emulator.stdout.readline().rsplit("--tracker ", 1)[1].strip()
        assert spec.startswith("serial:socket://")
        done = subprocess.run([*RIG, "check", "--tracker", spec, "--camera", f"camera:{film}", "--out", str(tmp_path / "run"), "--json"],
                              capture_output=True, text=True, timeout=300)  # fmt: skip
        emulator.wait(timeout=60)
    finally:
        if emulator.poll() is None:
            emulator.kill()
            emulator.wait()
        emulator.stdout.close()
    assert done.returncode == 4, done.stderr
    report = json.loads(done.stdout)
    rows = {(row["device"], row["what"]): row for row in report["checks"]}
    assert report["status"] == FAIL and rows["display", "opens, swaps paced"]["status"] == FAIL
    assert "vsync" in rows["display", "opens, swaps paced"]["measured"] or "not regular" in rows["display", "opens, swaps paced"]["measured"]
    assert rows["tracker", "rate"]["values"]["rate_hz"] == pytest.approx(TRACKER_HZ, rel=0.01)
    assert rows["camera", "frame rate"]["status"] == PASS and rows["disk", "room for the film"]["status"] == PASS


def test_an_external_renderer_has_no_window_to_check(tmp_path: Path, film: Path) -> None:
    done = subprocess.run([*RIG, "check", "--external", "--camera", f"camera:{film}", "--duration", "10"],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert not any(" display " in line for line in lines)
    assert lines[-1].startswith("overall: pass (4 pass, 0 warn, 0 fail) in ")
