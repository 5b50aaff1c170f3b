"""The bad-input matrix: every command, given what a new user gets wrong, ends in one line on stderr
naming what was wrong, exit status 2, and leaves everything the user had (inputs, files already in
the output location) as it was. Commands run in this process through `rig.cli.main`."""

from __future__ import annotations

import math
import socket
import threading
from pathlib import Path
from typing import Callable, Iterator

import cv2
import numpy as np
import pytest

HEADER = "t,px,py,pz,qw,qx,qy,qz"
FRAME = (48, 64)


def _video(path: Path, frame: Callable[[int], np.ndarray], frames: int = 40) -> Path:
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 60.0, (FRAME[1], FRAME[0]))
    for i in range(frames):
        writer.write(frame(i))
    writer.release()
    return path


def _flat(level: int) -> Callable[[int], np.ndarray]:
    return lambda i: np.full((*FRAME, 3), level, np.uint8)


def _one_blob(i: int) -> np.ndarray:
    image = np.zeros((*FRAME, 3), np.uint8)
    cv2.circle(image, (int(32 + 20 * math.sin(i / 5)), 24), 4, (255, 255, 255), -1)
    return image


def _trace(path: Path, times: list[float]) -> Path:
    rows = "".join(f"{t!r},{math.sin(t)},0,0,1,0,0,0\n" for t in times)
    path.write_text(f"{HEADER}\n{rows}")
    return path


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """What a user has lying about: videos, traces, parameter files, sweep specs, a file, a folder
    already holding a run."""
    lab = tmp_path_factory.mktemp("lab")
    _video(lab / "black.avi", _flat(0))
    _video(lab / "white.avi", _flat(255))
    _video(lab / "grey.avi", _flat(128))
    blob = _video(lab / "blob.avi", _one_blob).read_bytes()
    (lab / "truncated.avi").write_bytes(blob[: len(blob) // 3])
    (lab / "empty.avi").write_bytes(b"")
    (lab / "corrupt.avi").write_bytes(bytes(range(256)) * 40)
    (lab / "notes.mp4").write_text("these are my notes, not a video\n" * 50)
    (lab / "mixed").mkdir()
    cv2.imwrite(str(lab / "mixed" / "001.png"), _flat(0)(0))
    (lab / "mixed" / "002.txt").write_text("not an image")
    cv2.imwrite(str(lab / "mixed" / "003.jpg"), np.zeros((30, 20, 3), np.uint8))
    (lab / "no-images").mkdir()
    times = [i * 0.01 for i in range(300)]
    _trace(lab / "good.csv", times)
    (lab / "nan.csv").write_text(f"{HEADER}\n0,0,0,0,1,0,0,0\n0.01,0,0,0,nan,0,0,0\n0.02,0,0,0,1,0,0,0\n")
    (lab / "missing-column.csv").write_text("t,px,py,qw,qx,qy,qz\n0,0,0,1,0,0,0\n")
    (lab / "wrong-header.csv").write_text("time;x;y\n0;1;2\n")
    swapped = times.copy()
    swapped[10], swapped[20] = swapped[20], swapped[10]
    _trace(lab / "unsorted.csv", swapped)
    _trace(lab / "duplicate.csv", [*times[:50], times[50], *times[50:]])
    _trace(lab / "one-row.csv", [0.0])
    (lab / "empty.csv").write_text("")
    (lab / "unknown-key.json").write_text('{"nonsense": 1}')
    (lab / "wrong-type.json").write_text('{"position_noise": "abc"}')
    (lab / "out-of-range.json").write_text('{"position_noise": -5}')
    (lab / "broken.json").write_text("{not json")
    (lab / "unknown-key.toml").write_text('[base]\nduration_s = 2\nbogus = 1\n[grid]\n"camera.fps" = [120]\n')
    (lab / "wrong-type.toml").write_text('[base]\nduration_s = "two"\n[grid]\n"camera.fps" = [120]\n')
    (lab / "out-of-range.toml").write_text('[base]\nduration_s = 2\n[grid]\n"pendulum.amplitude_deg" = [90]\n')
    (lab / "not.toml").write_text("this is = not toml [")
    (lab / "good.toml").write_text('[base]\nduration_s = 3\n[grid]\n"camera.fps" = [120]\n')
    (lab / "old-sweep").mkdir()
    (lab / "old-sweep" / "summary.csv").write_text("the user's summary")
    (lab / "a-file").write_text("precious")
    (lab / "no-video-column.csv").write_text("name,latency_ms\na,1.0\n")
    run = lab / "old-run"
    run.mkdir()
    for name in ("video.avi", "truth.json", "tracker.csv", "notes.txt"):
        (run / name).write_text(f"the user's {name}")
    return lab


@pytest.fixture
def silent_board() -> Iterator[str]:
    """A socket:// port that accepts the connection and never says a word."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        accepted: list[socket.socket] = []
        thread = threading.Thread(target=lambda: accepted.append(server.accept()[0]), name="silent board")
        thread.start()
        yield f"socket://127.0.0.1:{server.getsockname()[1]}"
        thread.join(timeout=10)
        for connection in accepted:
            connection.close()


@pytest.fixture
def babbling_board() -> Iterator[str]:
    """A socket:// port that answers every request with bytes that are no frame of the protocol."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        stop = threading.Event()

        def babble() -> None:
            connection = server.accept()[0]
            connection.settimeout(0.05)
            noise = np.random.default_rng(7)
            with connection:
                while not stop.is_set():
                    try:
                        connection.recv(256)
                    except TimeoutError:
                        pass
                    try:
                        connection.sendall(noise.integers(0, 256, 64, dtype=np.uint8).tobytes())
                    except OSError:
                        return

        thread = threading.Thread(target=babble, name="babbling board")
        thread.start()
        yield f"socket://127.0.0.1:{server.getsockname()[1]}"
        stop.set()
        thread.join(timeout=10)


# (id, argv with {lab} for the lab folder, a word the message must hold)
CASES = [
    # simulate: where it writes, what it simulates
    ("simulate-out-is-a-file", "simulate --out {lab}/a-file --duration 1", "is a file"),
    ("simulate-out-unwritable", "simulate --out /proc/rig-run --duration 1", "cannot write"),
    ("simulate-out-holds-a-run", "simulate --out {lab}/old-run --duration 1", "--overwrite"),
    ("simulate-amplitude-out-of-range", "simulate --out {lab}/new --amplitude-deg 80", "--amplitude-deg"),
    ("simulate-duration-too-short", "simulate --out {lab}/new --duration 0.1", "duration"),
    ("simulate-unknown-renderer", "simulate --out {lab}/new --renderer teapot", "unknown renderer"),
    ("simulate-unknown-predictor", "simulate --out {lab}/new --predictor oracle", "unknown predictor"),
    ("simulate-params-unknown-key", "simulate --out {lab}/new --predictor kalman-cv:{lab}/unknown-key.json", "nonsense"),
    ("simulate-params-wrong-type", "simulate --out {lab}/new --predictor kalman-cv:{lab}/wrong-type.json", "position_noise"),
    ("simulate-params-out-of-range", "simulate --out {lab}/new --predictor kalman-cv:{lab}/out-of-range.json", "position_noise"),
    ("simulate-params-not-json", "simulate --out {lab}/new --predictor kalman-cv:{lab}/broken.json", "--predictor"),
    ("simulate-plot-unknown-format", "simulate --out {lab}/new --plot {lab}/truth.jpgx", "--plot"),
    ("simulate-plot-is-a-folder", "simulate --out {lab}/new --plot {lab}/mixed", "is a folder"),
    ("simulate-negative-number", "simulate --out {lab}/new --tracker-hz -5", "--tracker-hz"),
    ("demo-out-is-a-file", "demo --out {lab}/a-file --duration 1", "is a file"),
    ("demo-unknown-renderer", "demo --out {lab}/new --renderer teapot", "unknown renderer"),
    # analyse: what it is given to film
    ("analyse-missing-file", "analyse {lab}/nothing.avi", "does not exist"),
    ("analyse-empty-file", "analyse {lab}/empty.avi", "empty.avi"),
    ("analyse-truncated-video", "analyse {lab}/truncated.avi", "truncated.avi"),
    ("analyse-corrupt-video", "analyse {lab}/corrupt.avi", "corrupt.avi"),
    ("analyse-not-a-video", "analyse {lab}/notes.mp4", "notes.mp4"),
    ("analyse-one-blob", "analyse {lab}/blob.avi", "1 moving"),
    ("analyse-no-blob", "analyse {lab}/grey.avi", "0 moving"),
    ("analyse-all-black", "analyse {lab}/black.avi", "0 moving"),
    ("analyse-all-white", "analyse {lab}/white.avi", "0 moving"),
    ("analyse-mixed-images", "analyse {lab}/mixed --fps 30", "mixed"),
    ("analyse-folder-without-images", "analyse {lab}/no-images --fps 30", "no-images"),
    ("analyse-negative-roi", "analyse {lab}/blob.avi --led-roi=-1,0,10,10 --sphere-roi 0,0,10,10", "--led-roi"),
    ("analyse-roi-value-like-an-option", "analyse {lab}/blob.avi --led-roi -1,0,10,10", "--led-roi=VALUE"),
    ("analyse-one-roi-only", "analyse {lab}/blob.avi --led-roi 0,0,10,10", "--sphere-roi"),
    ("analyse-unknown-method", "analyse {lab}/blob.avi --method astrology", "--method"),
    ("analyse-latency-range-backwards", "analyse {lab}/blob.avi --latency-range 50,1", "--latency-range"),
    ("analyse-plot-unknown-format", "analyse {lab}/blob.avi --plot {lab}/tracks.jpgx", "--plot"),
    ("analyse-plot-is-a-folder", "analyse {lab}/blob.avi --plot {lab}/mixed", "is a folder"),
    ("analyse-csv-folder-missing", "analyse {lab}/blob.avi --csv {lab}/nowhere/tracks.csv", "does not exist"),
    ("analyse-summary-over-a-file", "analyse {lab}/blob.avi {lab}/grey.avi --summary {lab}/a-file", "--summary"),
    # calibrate-camera: the film of a flashing light
    ("calibrate-camera-missing-file", "calibrate-camera {lab}/nothing.avi --flash-hz 80", "does not exist"),
    ("calibrate-camera-corrupt-video", "calibrate-camera {lab}/corrupt.avi --flash-hz 80", "corrupt.avi"),
    ("calibrate-camera-no-flashing-light", "calibrate-camera {lab}/grey.avi --flash-hz 80", "no flashing light"),
    ("calibrate-camera-no-flash-frequency", "calibrate-camera {lab}/grey.avi", "--flash-hz"),
    ("calibrate-camera-duty-out-of-range", "calibrate-camera {lab}/grey.avi --flash-hz 80 --duty 1.5", "--duty"),
    ("calibrate-camera-display-without-its-rate", "calibrate-camera {lab}/grey.avi --flash-hz 30 --source display", "--display-hz"),
    # tune: traces and where the parameters go
    ("tune-trace-with-nan", "tune kalman-cv --trace {lab}/nan.csv --horizon-ms 20 --out {lab}/p.json", "finite"),
    ("tune-trace-missing-column", "tune kalman-cv --trace {lab}/missing-column.csv --horizon-ms 20 --out {lab}/p.json", "pz"),
    ("tune-trace-wrong-header", "tune kalman-cv --trace {lab}/wrong-header.csv --horizon-ms 20 --out {lab}/p.json", "header"),
    ("tune-trace-unsorted", "tune kalman-cv --trace {lab}/unsorted.csv --horizon-ms 20 --out {lab}/p.json", "--repair"),
    ("tune-trace-duplicate-times", "tune kalman-cv --trace {lab}/duplicate.csv --horizon-ms 20 --out {lab}/p.json", "same time"),
    ("tune-trace-one-row", "tune kalman-cv --trace {lab}/one-row.csv --horizon-ms 20 --out {lab}/p.json", "one-row"),
    ("tune-trace-empty", "tune kalman-cv --trace {lab}/empty.csv --horizon-ms 20 --out {lab}/p.json", "empty"),
    ("tune-trace-missing", "tune kalman-cv --trace {lab}/nothing.csv --horizon-ms 20 --out {lab}/p.json", "nothing.csv"),
    ("tune-out-folder-missing", "tune kalman-cv --trace {lab}/good.csv --horizon-ms 20 --out {lab}/nowhere/p.json", "does not exist"),
    ("tune-out-is-a-folder", "tune kalman-cv --trace {lab}/good.csv --horizon-ms 20 --out {lab}/mixed", "is a folder"),
    ("tune-untunable-predictor", "tune hold --trace {lab}/good.csv --horizon-ms 20 --out {lab}/p.json", "tunable"),
    # bench
    ("bench-predictors-trace-with-nan", "bench predictors --trace {lab}/nan.csv", "finite"),
    ("bench-predictors-unknown-predictor", "bench predictors --predictor oracle", "unknown predictor"),
    ("bench-predictors-plot-unknown-format", "bench predictors --plot {lab}/speed.jpgx", "--plot"),
    ("bench-predictors-json-is-a-folder", "bench predictors --json {lab}/mixed", "is a folder"),
    ("bench-predictors-corpus-missing", "bench predictors --corpus {lab}/nowhere", "is not a folder"),
    ("bench-predictors-cross-validate-without-corpus", "bench predictors --cross-validate", "need --corpus"),
    ("bench-analyser-json-folder-missing", "bench analyser --quick --json {lab}/nowhere/a.json", "does not exist"),
    ("bench-renderers-csv-wrong-extension", "bench renderers --quick --csv {lab}/rows.txt", "--csv"),
    ("bench-trackers-runs-is-a-file", "bench trackers --quick --runs {lab}/a-file", "is a file"),
    ("bench-live-plot-is-a-folder", "bench live --plot {lab}/mixed", "is a folder"),
    # sweep
    ("sweep-unknown-key", "sweep {lab}/unknown-key.toml --out {lab}/sweep", "bogus"),
    ("sweep-wrong-type", "sweep {lab}/wrong-type.toml --out {lab}/sweep", "duration"),
    ("sweep-out-of-range", "sweep {lab}/out-of-range.toml --out {lab}/sweep", "amplitude"),
    ("sweep-not-toml", "sweep {lab}/not.toml --out {lab}/sweep", "TOML"),
    ("sweep-missing-spec", "sweep {lab}/nothing.toml --out {lab}/sweep", "nothing.toml"),
    ("sweep-out-is-a-file", "sweep {lab}/unknown-key.toml --out {lab}/a-file", "is a file"),
    ("sweep-out-holds-a-sweep", "sweep {lab}/good.toml --out {lab}/old-sweep", "--overwrite"),
    # report
    ("report-missing-source", "report {lab}/nothing --out {lab}/r.html", "does not exist"),
    ("report-out-not-html", "report {lab}/old-run --out {lab}/r.htm", ".html"),
    ("report-summary-without-videos", "report {lab}/no-video-column.csv --out {lab}/r.html", "video column"),
    ("report-corrupt-video", "report {lab}/corrupt.avi --out {lab}/r.html", "corrupt.avi"),
    # plan
    ("plan-camera-rate-out-of-range", "plan --display-hz 60 --camera-fps 5000", "20-2000"),
    ("plan-exposure-out-of-range", "plan --display-hz 60 --camera-fps 120 --exposures 2", "(0, 1]"),
    ("plan-runs-is-a-file", "plan --display-hz 60 --camera-fps 120 --runs {lab}/a-file", "is a file"),
    # devices, trackers, cameras, the live rig
    ("devices-negative-wait", "devices --lsl-wait=-1", "--lsl-wait"),
    ("record-tracker-unknown-device", "record-tracker --tracker teleport:x --out {lab}/rec --duration 1", "unknown tracker"),
    ("record-tracker-out-is-a-file", "record-tracker --tracker serial:loop:// --out {lab}/a-file --duration 1", "is a file"),
    ("emulate-tracker-trace-with-nan", "emulate-tracker serial --tcp 0 --duration 1 --trace {lab}/nan.csv", "finite"),
    ("emulate-tracker-log-not-csv", "emulate-tracker serial --tcp 0 --duration 1 --log {lab}/log.txt", "--log"),
    ("record-missing-video", "record --camera camera:{lab}/nothing.avi --duration 1 --out {lab}/film", "nothing.avi"),
    ("record-corrupt-video", "record --camera camera:{lab}/corrupt.avi --duration 1 --out {lab}/film", "corrupt.avi"),
    ("measure-without-devices", "measure --out {lab}/measured", "--tracker"),
    ("measure-out-is-a-file", "measure --tracker serial:loop:// --camera camera:0 --out {lab}/a-file", "is a file"),
    ("check-unknown-tracker", "check --tracker teleport:x --external", "unknown tracker"),
    ("check-out-is-a-file", "check --external --out {lab}/a-file", "is a file"),
    # the board
    ("board-latency-missing-recording", "board latency {lab}/nothing", "nothing"),
    ("board-latency-plot-unknown-format", "board latency {lab}/old-run --plot {lab}/fit.jpgx", "--plot"),
    ("board-record-out-is-a-file", "board record --port loop:// --out {lab}/a-file --duration 1", "is a file"),
    ("unknown-command", "teleport", "invalid choice"),
]


@pytest.mark.parametrize("argv, word", [pytest.param(argv, word, id=name) for name, argv, word in CASES])
def test_bad_input_is_one_line_and_loses_nothing(
    assert_one_line_error: Callable[..., None],
    run_rig: Callable[..., tuple[int, str, str]],
    snapshot: Callable[[Path], dict[Path, str]],
    argv: str,
    word: str,
    lab: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    before = snapshot(lab)
    code, _, err = run_rig(argv.format(lab=lab).split(), capsys)
    assert_one_line_error(code, err, word)
    assert {path: digest for path, digest in snapshot(lab).items() if path in before} == before


def test_a_board_that_says_nothing(
    assert_one_line_error: Callable[..., None],
    run_rig: Callable[..., tuple[int, str, str]], silent_board: str, capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = run_rig(["board", "info", "--port", silent_board], capsys)
    assert_one_line_error(code, err, "did not answer")


def test_a_board_that_answers_garbage(
    assert_one_line_error: Callable[..., None],
    run_rig: Callable[..., tuple[int, str, str]], babbling_board: str, capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = run_rig(["board", "info", "--port", babbling_board], capsys)
    assert_one_line_error(code, err, "did not answer")


def test_matrix_covers_every_command() -> None:
    from rig.cli import COMMANDS

    tried = {argv.split()[0] for _, argv, _ in CASES}
    assert {name.replace("_", "-") for name in COMMANDS} - tried <= {"emulate"}
    assert "emulate-tracker" in tried
    assert len(CASES) + 2 >= 40
