"""Ctrl-C and SIGTERM at several moments of each long command, run as a user runs it (the console
script, in its own process): it exits 130 (143 for SIGTERM), never crashes (no signal death) or
hangs, and leaves what it wrote readable: every CSV complete to its last row, every video playing to
the last frame written, every JSON parseable, and a JSON written over an interrupted run marked partial.

`interrupt_storm.py` beside this file runs the same commands and checks, interrupted at random
moments, many times over.
"""

from __future__ import annotations

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import cv2
import pytest

RIG = Path(sys.executable).with_name("rig")
EXIT_FOR = {signal.SIGINT: 130, signal.SIGTERM: 143}
STOP_LIMIT_S = 30.0
"""A command still running this long after the signal hangs (generous: the CI machine is shared)."""
START_LIMIT_S = 120.0


_STARTED: list[Run] = []


@pytest.fixture(autouse=True)
def _no_command_left_running() -> Iterator[None]:
    """A test that fails before stopping its command must not leave it running (recording for ever)."""
    yield
    while _STARTED:
        _STARTED.pop().kill()


@dataclass
class Run:
    """A rig command started in its own process, its output going to files."""

    argv: list[str]
    folder: Path
    process: subprocess.Popen = field(init=False)

    def __post_init__(self) -> None:
        self.folder.mkdir(parents=True, exist_ok=True)
        self._out = open(self.folder.parent / f"{self.folder.name}.stdout", "w")
        self._err = open(self.folder.parent / f"{self.folder.name}.stderr", "w")
        # Unbuffered, so that what the command printed before a signal is in its file at once.
        env = {**os.environ, "PYTHONFAULTHANDLER": "1", "PYTHONUNBUFFERED": "1"}
        self.process = subprocess.Popen([str(RIG), *self.argv], stdout=self._out, stderr=self._err, env=env)
        _STARTED.append(self)

    def kill(self) -> None:
        """End the command if a failed test left it running."""
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()
        self._out.close()
        self._err.close()

    def wait_for(self, moment: Callable[[], bool], limit_s: float = START_LIMIT_S) -> bool:
        """True once `moment` holds while the command runs; False if it ended first."""
        deadline = time.monotonic() + limit_s
        while self.process.poll() is None:
            if moment():
                return True
            if time.monotonic() > deadline:
                raise AssertionError(f"rig {' '.join(self.argv)}: the moment never came in {limit_s:g} s")
            time.sleep(0.02)
        return False

    def stop(self, sig: signal.Signals = signal.SIGINT) -> tuple[int, float]:
        """Send `sig`; the exit status and the seconds the command took to end. A hang fails."""
        sent = time.monotonic()
        self.process.send_signal(sig)
        try:
            code = self.process.wait(timeout=STOP_LIMIT_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise AssertionError(f"rig {' '.join(self.argv)} hung after {sig.name}") from None
        finally:
            self._out.close()
            self._err.close()
        return code, time.monotonic() - sent

    @property
    def stderr(self) -> str:
        return (self.folder.parent / f"{self.folder.name}.stderr").read_text()

    def printed(self, text: str) -> Callable[[], bool]:
        """The moment the command has printed `text`: its own code runs, its handlers in place (a
        signal before that, while a loaded machine still starts Python, is Python's to handle)."""
        return lambda: text in (self.folder.parent / f"{self.folder.name}.stdout").read_text()


def file_with_rows(path: Path, rows: int = 1) -> Callable[[], bool]:
    """The moment `path` holds `rows` data rows (lines after the header)."""

    def moment() -> bool:
        try:
            return path.read_bytes().count(b"\n") > rows
        except OSError:
            return False

    return moment


def after(seconds: float) -> Callable[[], bool]:
    deadline = time.monotonic() + seconds
    return lambda: time.monotonic() >= deadline


def unreadable(folder: Path) -> list[str]:
    """What in `folder` a user could not read back: each problem in a line."""
    problems = []
    for path in sorted(folder.rglob("*.csv")):
        text = path.read_text(encoding="utf-8")
        if not text:
            continue
        if not text.endswith("\n"):
            problems.append(f"{path}: the last row is cut short")
        rows = list(csv.reader(text.splitlines()))
        widths = {len(row) for row in rows}
        if len(widths) > 1:
            problems.append(f"{path}: rows of {sorted(widths)} fields")
    for path in sorted(folder.rglob("*.avi")):
        capture = cv2.VideoCapture(str(path))
        indexed = int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
        played = 0
        while capture.isOpened() and capture.read()[0]:
            played += 1
        capture.release()
        if played != indexed:
            problems.append(f"{path}: {played} of its {indexed} frames play")
    for path in sorted(folder.rglob("*.json")):
        try:
            json.loads(path.read_text(encoding="utf-8"))
        except ValueError as error:
            problems.append(f"{path}: {error}")
    return problems


def assert_stopped_cleanly(run: Run, code: int, sig: signal.Signals = signal.SIGINT) -> None:
    assert code == EXIT_FOR[sig], f"exit {code} after {sig.name}:\n{run.stderr}"
    assert "Traceback" not in run.stderr and "Fatal Python error" not in run.stderr, run.stderr
    assert unreadable(run.folder) == []


@pytest.fixture(scope="module")
def video(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An 8 s film at 120 fps of the simulated rig."""
    out = tmp_path_factory.mktemp("film")
    subprocess.run([str(RIG), "simulate", "--out", str(out), "--duration", "8", "--camera-fps", "120", "--overwrite"],
                   check=True, capture_output=True)  # fmt: skip
    return out / "video.avi"


@pytest.fixture(scope="module")
def trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two minutes of a swinging, turning head at 100 Hz."""
    path = tmp_path_factory.mktemp("trace") / "head.csv"
    rows = []
    for i in range(12000):
        t = i / 100
        angle = 0.4 * math.sin(2 * math.pi * 0.7 * t) + 0.1 * math.sin(2 * math.pi * 2.3 * t)
        rows.append(f"{t!r},{0.1 * math.sin(t)},{0.02 * math.cos(3 * t)},0,{math.cos(angle / 2)!r},0,{math.sin(angle / 2)!r},0\n")
    path.write_text("t,px,py,pz,qw,qx,qy,qz\n" + "".join(rows))
    return path


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_simulate_stopped_while_filming(sig: signal.Signals, tmp_path: Path) -> None:
    run = Run(["simulate", "--out", str(tmp_path / "run"), "--duration", "30"], tmp_path / "run")
    assert run.wait_for(file_with_rows(tmp_path / "run" / "display_frames.csv", 20))
    code, _ = run.stop(sig)
    assert_stopped_cleanly(run, code, sig)
    assert (tmp_path / "run" / "video.avi").exists()


def test_simulate_stopped_with_frames_filmed(tmp_path: Path) -> None:
    run = Run(["simulate", "--out", str(tmp_path / "run"), "--duration", "30"], tmp_path / "run")
    assert run.wait_for(file_with_rows(tmp_path / "run" / "display_frames.csv", 120))
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)
    assert cv2.VideoCapture(str(tmp_path / "run" / "video.avi")).get(cv2.CAP_PROP_FRAME_COUNT) > 0


def test_simulate_stopped_at_once(tmp_path: Path) -> None:
    run = Run(["simulate", "--out", str(tmp_path / "run"), "--duration", "30"], tmp_path / "run")
    assert run.wait_for(after(0.3))
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)


@pytest.mark.slow
@pytest.mark.parametrize("moment", ["tracking", "fitting"])
def test_analyse_stopped_while_tracking_or_fitting(moment: str, video: Path, tmp_path: Path) -> None:
    tracks = tmp_path / "out" / "tracks.csv"
    run = Run(["analyse", str(video), "--csv", str(tracks), "--method", "all"], tmp_path / "out")
    frames = int(cv2.VideoCapture(str(video)).get(cv2.CAP_PROP_FRAME_COUNT))
    rows = 50 if moment == "tracking" else frames
    if not run.wait_for(file_with_rows(tracks, rows)):
        pytest.fail(f"rig analyse ended before {moment}:\n{run.stderr}")
    if moment == "fitting":
        run.wait_for(after(0.3))
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)


@pytest.mark.slow
def test_demo_stopped_while_measuring(tmp_path: Path) -> None:
    run = Run(["demo", "--out", str(tmp_path / "demo"), "--duration", "6"], tmp_path / "demo")
    if not run.wait_for(lambda: (tmp_path / "demo" / "truth.json").exists()):
        pytest.fail(f"rig demo ended before it analysed:\n{run.stderr}")
    run.wait_for(after(0.5))
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)


@pytest.mark.slow
@pytest.mark.parametrize("wait_s", [0.5, 3.0])
def test_tune_stopped_while_compiling_or_fitting(wait_s: float, trace: Path, tmp_path: Path) -> None:
    """Stopped `wait_s` after it says it is tuning: while JAX loads and compiles, or while it fits
    (2000 iterations: longer than any wait here)."""
    out = tmp_path / "tuned" / "params.json"
    run = Run(["tune", "kalman-cv", "--trace", str(trace), "--horizon-ms", "30", "--max-iterations", "2000", "--out", str(out)],
              tmp_path / "tuned")  # fmt: skip
    if not run.wait_for(run.printed("tuning kalman-cv")) or not run.wait_for(after(wait_s)):
        pytest.fail(f"rig tune ended within {wait_s} s:\n{run.stderr}")
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)
    assert not out.exists()


@pytest.mark.slow
def test_sweep_stopped_after_a_point(tmp_path: Path) -> None:
    spec = tmp_path / "sweep.toml"
    spec.write_text('[base]\nduration_s = 3\n[grid]\n"camera.fps" = [120, 180, 240, 300]\n')
    out = tmp_path / "sweep"
    run = Run(["sweep", str(spec), "--out", str(out)], out)
    if not run.wait_for(file_with_rows(out / "summary.csv", 1)):
        pytest.fail(f"rig sweep ended before its first point:\n{run.stderr}")
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)
    assert json.loads((out / "summary.json").read_text())["partial"] is True


@pytest.mark.slow
def test_bench_stopped_while_benchmarking(tmp_path: Path) -> None:
    run = Run(["bench", "predictors", "--duration", "20", "--json", str(tmp_path / "bench" / "b.json")], tmp_path / "bench")
    if not run.wait_for(after(3.0)):
        pytest.fail(f"rig bench predictors ended within 3 s:\n{run.stderr}")
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)


@pytest.mark.slow
def test_record_tracker_stopped_while_recording(tmp_path: Path) -> None:
    emulator = subprocess.Popen(
        [str(RIG), "emulate-tracker", "serial", "--pty", str(tmp_path / "tty"), "--rate", "500", "--profile", "binary-pose"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + START_LIMIT_S
        while not (tmp_path / "tty").exists():
            assert emulator.poll() is None and time.monotonic() < deadline, "the emulated tracker did not start"
            time.sleep(0.05)
        out = tmp_path / "rec"
        run = Run(["record-tracker", "--tracker", f"serial:{tmp_path / 'tty'}?profile=binary-pose", "--out", str(out)], out)
        if not run.wait_for(file_with_rows(out / "tracker.csv", 100)):
            pytest.fail(f"rig record-tracker ended before recording:\n{run.stderr}")
        code, _ = run.stop()
        assert_stopped_cleanly(run, code)
        sidecar = json.loads((out / "tracker.json").read_text())
        assert sidecar["partial"] is True
        assert sidecar["samples"] == len((out / "tracker.csv").read_text().splitlines()) - 1
    finally:
        emulator.send_signal(signal.SIGINT)
        emulator.wait(timeout=STOP_LIMIT_S)


@pytest.mark.slow
def test_record_stopped_while_filming(video: Path, tmp_path: Path) -> None:
    out = tmp_path / "film"
    run = Run(["record", "--camera", f"camera:{video}", "--duration", "60", "--out", str(out)], out)
    if not run.wait_for(file_with_rows(out / "camera_frames.csv", 30)):
        pytest.fail(f"rig record ended before filming:\n{run.stderr}")
    code, _ = run.stop()
    assert_stopped_cleanly(run, code)
    assert json.loads((out / "camera.json").read_text())["partial"] is True
