"""Names the system accepts but the video libraries cannot open, paths the emulator must not take
over, runs that fail before recording anything, and waits a signal must end.

A file name that is not UTF-8 crashed OpenCV (a segmentation fault, no message), so those commands
run in their own process, where a crash shows as a signal death; the others run in this process
through `rig.cli.main`, as tests/cli/test_bad_input.py does. Each ends in one line on stderr naming
what was wrong, exit status 2, and leaves the user's files as they were; a run that failed before
recording anything leaves nothing, so the same command can be run again.
"""

from __future__ import annotations

import csv
import math
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Callable, Iterator

import cv2
import numpy as np
import pytest

from rig.cli import EXIT_INTERRUPTED, EXIT_TERMINATED
from rig.fresh_outputs import removed_unless_recorded

RIG = Path(sys.executable).with_name("rig")
COMMAND_LIMIT_S = 60.0
"""A command still running this long hangs (generous: imports on a shared machine)."""
STOP_LIMIT_S = 1.0
"""How soon a wait must end once signalled."""
FRAME = (48, 64)
NOT_UTF8 = os.fsdecode(b"caf\xe9")
"""The str Python gives for the bytes b"caf\\xe9" in a file name (a surrogate for the \\xe9)."""


def _video(path: Path) -> None:
    writer = cv2.VideoWriter(os.fsencode(path).decode(), cv2.VideoWriter_fourcc(*"MJPG"), 60.0, (FRAME[1], FRAME[0]))
    for i in range(20):
        image = np.zeros((*FRAME, 3), np.uint8)
        cv2.circle(image, (int(32 + 20 * math.sin(i / 5)), 24), 4, (255, 255, 255), -1)
        writer.write(image)
    writer.release()


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A lab folder with videos and image folders named in bytes that are not UTF-8 (written under
    a UTF-8 name, then renamed: OpenCV cannot write them either)."""
    lab = tmp_path_factory.mktemp("lab")
    _video(lab / "blob.avi")
    _video(lab / "staged.avi")
    os.rename(lab / "staged.avi", lab / f"{NOT_UTF8}.avi")
    frames = lab / "frames"
    frames.mkdir()
    for number in range(3):
        cv2.imwrite(str(frames / f"frame_{number:03d}.png"), np.zeros((*FRAME, 3), np.uint8))
    os.rename(frames / "frame_001.png", frames / f"{NOT_UTF8}_001.png")
    images = lab / "images"
    images.mkdir()
    cv2.imwrite(str(images / "frame_000.png"), np.zeros((*FRAME, 3), np.uint8))
    os.rename(images, lab / f"{NOT_UTF8}-images")
    (lab / f"{NOT_UTF8}-empty").mkdir()
    (lab / "good.toml").write_text('[base]\nduration_s = 2\n[grid]\n"camera.fps" = [120]\n')
    (lab / "a-file").write_text("precious")
    os.symlink(lab / "a-file", lab / "a-link")
    (lab / "empty-folder").mkdir()
    return lab


def _listing(folder: Path) -> set[Path]:
    return set(folder.rglob("*"))


def _rig_process(argv: list[str], cwd: Path) -> tuple[int, str, str]:
    """The console script in its own process: a crash is a negative status, not this test's death."""
    done = subprocess.run([str(RIG), *argv], cwd=cwd, capture_output=True, timeout=COMMAND_LIMIT_S, env={**os.environ, "PYTHONFAULTHANDLER": "1"})
    return done.returncode, done.stdout.decode(errors="backslashreplace"), done.stderr.decode(errors="backslashreplace")


def _closed_port() -> int:
    """A port on this machine that nobody listens at."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        return server.getsockname()[1]


@pytest.fixture
def silent_port() -> Iterator[str]:
    """A socket:// port that accepts connections and never says a word."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        server.settimeout(0.1)
        stop = threading.Event()
        accepted: list[socket.socket] = []

        def accept() -> None:
            while not stop.is_set():
                try:
                    accepted.append(server.accept()[0])
                except TimeoutError:
                    pass

        thread = threading.Thread(target=accept, name="silent device")
        thread.start()
        yield f"socket://127.0.0.1:{server.getsockname()[1]}"
        stop.set()
        thread.join(timeout=10)
        for connection in accepted:
            connection.close()


# (id, argv with {lab} for the lab folder and {bad} for the name in bytes that are not UTF-8, a word the message must hold)
NAME_CASES = [
    ("analyse-video-named-in-latin-1", "analyse {lab}/{bad}.avi", "caf\\xe9.avi: the name is not valid UTF-8"),
    ("analyse-image-folder-named-in-latin-1", "analyse {lab}/{bad}-images --fps 30", "caf\\xe9-images"),
    ("analyse-image-named-in-latin-1", "analyse {lab}/frames --fps 30", "caf\\xe9_001.png"),
    ("calibrate-camera-video-named-in-latin-1", "calibrate-camera {lab}/{bad}.avi --flash-hz 80", "not valid UTF-8"),
    ("record-camera-file-named-in-latin-1", "record --camera camera:{lab}/{bad}.avi --duration 1 --out {lab}/film", "caf\\xe9.avi"),
    ("simulate-out-named-in-latin-1", "simulate --out {lab}/{bad}-run --duration 1", "caf\\xe9-run"),
    ("simulate-out-below-a-folder-named-in-latin-1", "simulate --out {lab}/{bad}-new/run --duration 1", "caf\\xe9-new"),
    ("simulate-out-an-existing-folder-named-in-latin-1", "simulate --out {lab}/{bad}-empty --duration 1", "caf\\xe9-empty"),
]


@pytest.mark.parametrize("argv, word", [pytest.param(argv, word, id=name) for name, argv, word in NAME_CASES])
def test_a_name_that_is_not_utf8_is_refused_in_one_line(
    assert_one_line_error: Callable[..., None],
    snapshot: Callable[[Path], dict[Path, str]],
    argv: str,
    word: str,
    lab: Path,
) -> None:
    before, listing = snapshot(lab), _listing(lab)
    code, _, err = _rig_process(argv.format(lab=lab, bad=NOT_UTF8).split(), lab)
    assert_one_line_error(code, err, word)
    assert snapshot(lab) == before
    assert _listing(lab) == listing, "a refused run left something behind"


def test_a_batch_goes_on_past_a_video_named_in_latin_1(lab: Path, tmp_path: Path) -> None:
    summary = tmp_path / "summary.csv"
    code, _, err = _rig_process(["analyse", str(lab / f"{NOT_UTF8}.avi"), str(lab / "blob.avi"), "--summary", str(summary)], lab)
    assert code >= 0, f"killed by signal {-code}:\n{err}"
    with summary.open(encoding="utf-8", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert [Path(row["video"]).name for row in rows] == ["caf\\xe9.avi", "blob.avi"]
    assert "not valid UTF-8" in rows[0]["error"]
    assert "not valid UTF-8" not in rows[1]["error"] and rows[1]["status"] in {"ok", "warning", "failed"}


# (id, argv, a word the message must hold)
EMULATOR_CASES = [
    ("emulate-pty-over-a-file", "emulate-tracker serial --pty {lab}/a-file --duration 1", "already exists"),
    ("emulate-pty-over-a-link", "emulate-tracker serial --pty {lab}/a-link --duration 1", "already exists"),
    ("emulate-pty-over-a-folder", "emulate-tracker serial --pty {lab}/empty-folder --duration 1", "already exists"),
    ("emulate-pty-in-a-missing-folder", "emulate-tracker serial --pty {lab}/nowhere/tty --duration 1", "does not exist"),
    ("emulate-tcp-port-out-of-range", "emulate-tracker serial --tcp 99999 --duration 1", "65535"),
    ("emulate-tcp-port-negative", "emulate-tracker serial --tcp=-1 --duration 1", "--tcp"),
]


@pytest.mark.parametrize("argv, word", [pytest.param(argv, word, id=name) for name, argv, word in EMULATOR_CASES])
def test_the_emulator_never_takes_a_path_over(
    assert_one_line_error: Callable[..., None],
    run_rig: Callable[..., tuple[int, str, str]],
    snapshot: Callable[[Path], dict[Path, str]],
    argv: str,
    word: str,
    lab: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    before, listing, link = snapshot(lab), _listing(lab), os.readlink(lab / "a-link")
    code, _, err = run_rig(argv.format(lab=lab).split(), capsys)
    assert_one_line_error(code, err, word)
    assert snapshot(lab) == before and _listing(lab) == listing
    assert (lab / "a-file").read_text() == "precious" and os.readlink(lab / "a-link") == link


# (id, argv with {lab}, {new} a folder that does not exist yet, {scheduler} an address nobody
# listens at and {port} a device that says nothing; a word the message must hold; the output)
RERUN_CASES = [
    ("sweep-scheduler-unreachable", "sweep {lab}/good.toml --out {new}/sweep --scheduler {scheduler}", "scheduler", "{new}"),
    ("sweep-into-an-existing-folder-scheduler-unreachable", "sweep {lab}/good.toml --out {lab}/empty-folder --scheduler {scheduler}",
     "scheduler", "{lab}/empty-folder"),  # fmt: skip
    ("batch-scheduler-unreachable", "analyse {lab}/blob.avi --summary {lab}/summary.csv --scheduler {scheduler}", "scheduler",
     "{lab}/summary.csv"),  # fmt: skip
    ("record-tracker-silent-tracker", "record-tracker --tracker serial:{port} --out {new}/rec --duration 0.5", "no sample", "{new}"),
    ("board-record-silent-board", "board record --port {port} --out {new}/board --duration 1", "did not answer", "{new}"),
]


@pytest.fixture
def impatient_scheduler_check(monkeypatch: pytest.MonkeyPatch) -> None:
    """A scheduler nobody listens at is given up at once, not after the 5 s a starting one gets."""
    import rig.executor

    monkeypatch.setattr(rig.executor._check_reachable, "__defaults__", (0.0,))


@pytest.mark.usefixtures("impatient_scheduler_check")
@pytest.mark.parametrize("argv, word, output", [pytest.param(a, w, o, id=name) for name, a, w, o in RERUN_CASES])
def test_a_run_that_recorded_nothing_leaves_nothing_and_runs_again(
    assert_one_line_error: Callable[..., None],
    run_rig: Callable[..., tuple[int, str, str]],
    snapshot: Callable[[Path], dict[Path, str]],
    argv: str, word: str, output: str, lab: Path, tmp_path: Path, silent_port: str, capsys: pytest.CaptureFixture[str]
) -> None:
    fill = {"lab": lab, "new": tmp_path / "new", "scheduler": f"tcp://127.0.0.1:{_closed_port()}", "port": silent_port}
    before, listing = snapshot(lab), _listing(lab)
    for attempt in ("first", "again"):
        code, _, err = run_rig(argv.format(**fill).split(), capsys)
        assert_one_line_error(code, err, word)
        assert "--overwrite" not in err, f"{attempt} run refused: {err}"
        assert snapshot(lab) == before and _listing(lab) == listing
        assert not (tmp_path / "new").exists()
    existed = Path(output.format(**fill))
    assert existed.exists() == (existed in listing)


def _csv(path: Path, rows: int) -> None:
    path.write_text("t,x\n" + "".join(f"{i},0\n" for i in range(rows)))


class Failed(Exception):
    pass


def _fail_after(outputs: list[Path], write: Callable[[], None]) -> None:
    """Run `write` as a run that then fails, its outputs watched by removed_unless_recorded."""
    with pytest.raises(Failed), removed_unless_recorded(*outputs):
        write()
        raise Failed


def test_a_failed_run_keeps_what_it_recorded(tmp_path: Path) -> None:
    run = tmp_path / "new" / "run"

    def record() -> None:
        run.mkdir(parents=True)
        _csv(run / "tracker.csv", 3)
        _csv(run / "app_frames.csv", 0)
        (run / "video.avi").write_bytes(b"RIFF")

    _fail_after([run], record)
    assert {p.name for p in run.iterdir()} == {"tracker.csv", "app_frames.csv", "video.avi"}


def test_a_failed_run_that_recorded_nothing_removes_only_what_it_made(tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    _csv(run / "notes.csv", 5)
    (run / "board").mkdir()

    def record() -> None:
        _csv(run / "tracker.csv", 0)
        (run / "board" / "led.csv").write_text("")
        (run / "new" / "deeper").mkdir(parents=True)
        (run / "tracker.json").write_text("{}")

    _fail_after([run], record)
    assert _listing(run) == {run / "notes.csv", run / "board"}
    assert (run / "notes.csv").read_text().count("\n") == 6


def test_a_failed_run_that_rewrote_a_table_with_rows_keeps_everything(tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    _csv(run / "tracker.csv", 0)

    def record() -> None:
        _csv(run / "tracker.csv", 2)
        (run / "video.avi").write_bytes(b"RIFF")

    _fail_after([run], record)
    assert {p.name for p in run.iterdir()} == {"tracker.csv", "video.avi"}


def test_a_failed_file_output_that_recorded_nothing_is_removed(tmp_path: Path) -> None:
    summary = tmp_path / "summary.csv"
    _fail_after([summary, summary.with_suffix(".json")], lambda: _csv(summary, 0))
    assert not summary.exists()
    assert list(tmp_path.iterdir()) == []


def _wait_for_library(process: subprocess.Popen, library: str) -> None:
    """Until `process` has loaded `library`: it is past its imports and into the work that uses it."""
    deadline = time.monotonic() + COMMAND_LIMIT_S
    maps = Path(f"/proc/{process.pid}/maps")
    while library not in maps.read_text():
        assert process.poll() is None, "the command ended before it waited"
        assert time.monotonic() < deadline, f"the command did not load {library}"
        time.sleep(0.05)


@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="finds when the wait starts in /proc")
@pytest.mark.parametrize("signum, status", [pytest.param(signal.SIGINT, EXIT_INTERRUPTED, id="sigint"),
                                            pytest.param(signal.SIGTERM, EXIT_TERMINATED, id="sigterm")])  # fmt: skip
def test_devices_listening_for_lsl_streams_stops_on_a_signal(signum: int, status: int, tmp_path: Path) -> None:
    process = subprocess.Popen([str(RIG), "devices", "--lsl-wait", "600"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        _wait_for_library(process, "liblsl")
        signalled = time.monotonic()
        process.send_signal(signum)
        _, err = process.communicate(timeout=COMMAND_LIMIT_S)
        took = time.monotonic() - signalled
    finally:
        process.kill()
        process.wait(timeout=COMMAND_LIMIT_S)
    assert process.returncode == status, err.decode()
    assert took < STOP_LIMIT_S, f"stopped {took:.1f} s after the signal"
    assert err.decode().strip().splitlines() == [f"rig devices: {'interrupted' if signum == signal.SIGINT else 'terminated'}; "
                                                 "everything recorded so far is on disk"]  # fmt: skip
