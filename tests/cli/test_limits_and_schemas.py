"""Limits before work, one schema per input: a number outside its physically meaningful range, a run
whose estimate cannot finish, or an input of the wrong shape ends in one line on stderr naming the
option or the key, the value and what is allowed, exit status 2, before any work and with nothing
written. Commands run in this process through `rig.cli.main`."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable

import cv2
import numpy as np
import pytest

from rig.cli import EXIT_USER_ERROR


@pytest.fixture(scope="module")
def lab(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """What a user has lying about: specs, summaries and traces of the wrong shape."""
    lab = tmp_path_factory.mktemp("lab")
    (lab / "a-file").write_text("precious")
    _trace(lab / "two-samples.csv", [0.0, 0.01])
    times = [i * 0.01 for i in range(300)]
    _trace(lab / "sorted.csv", times)
    times[10], times[20] = times[20], times[10]
    _trace(lab / "unsorted.csv", times)
    (lab / "base-a-number.toml").write_text('base = 5\n[grid]\n"camera.fps" = [120]\n')
    (lab / "grid-a-number.toml").write_text("grid = 5\n")
    (lab / "renderers-camera-a-number.toml").write_text("latency_camera = 5\n")
    (lab / "analysis-a-number.toml").write_text('analysis = 3\n[grid]\n"camera.fps" = [120]\n')
    (lab / "camera-a-number.toml").write_text('[base]\ncamera = 5\n[grid]\n"pendulum.period_s" = [1.0]\n')
    values = ", ".join(str(120 + i) for i in range(1000))
    (lab / "billion-points.toml").write_text(f'[grid]\n"camera.fps" = [{values}]\n"seed" = [{values}]\n"scene_triangles" = [{values}]\n')
    (lab / "renderers-beyond-a-day.toml").write_text(f"triangles = [{', '.join(['100000000'] * 50)}]\nwarp_rounds = 10000\n")
    (lab / "noise-beyond-a-metre.json").write_text('{"position_noise": 1e200}')
    (lab / "summary-a-list.json").write_text("[1, 2]")
    (lab / "summary-rows-a-number.json").write_text('{"rows": 5}')
    (lab / "summary-rows-of-numbers.json").write_text('{"rows": [1, 2]}')
    (lab / "summary-latency-a-table.json").write_text('{"rows": [{"video": "a.avi", "latency_ms": {"ms": 1}}]}')
    for name, truth in (("truncated-truth", '{"latency_ms": 31.2, "con'), ("truth-of-another-shape", '{"latency_ms": "31.2", "config": {}}')):
        (lab / name).mkdir()
        (lab / name / "video.avi").write_text("a film")
        (lab / name / "truth.json").write_text(truth)
    return lab


def _trace(path: Path, times: list[float]) -> None:
    rows = "".join(f"{t!r},{math.sin(t)},0,0,1,0,0,0\n" for t in times)
    path.write_text(f"t,px,py,pz,qw,qx,qy,qz\n{rows}")


# (id, argv with {lab} for the lab folder, words the message must hold)
CASES = [
    # simulate: each number within what a lab's rig can be
    ("simulate-negative-seed", "simulate --out {lab}/new --seed=-1", ("--seed", "from 0 to 1e+09", "-1")),
    ("simulate-tracker-rate-beyond-any-tracker", "simulate --out {lab}/new --tracker-hz 1e9", ("--tracker-hz", "from 1 to 5000", "1e9")),
    ("simulate-scene-beyond-any-gpu", "simulate --out {lab}/new --scene-triangles 1e12", ("--scene-triangles", "from 0 to 1e+08", "1e12")),
    ("simulate-app-frame-beyond-a-second", "simulate --out {lab}/new --app-frame-ms 1e9", ("--app-frame-ms", "at most 1000", "1e9")),
    ("simulate-period-too-short", "simulate --out {lab}/new --period-s 1e-9", ("--period-s", "from 0.2 to 20", "1e-9")),
    ("simulate-period-too-long", "simulate --out {lab}/new --period-s 1000", ("--period-s", "from 0.2 to 20", "1000")),
    ("simulate-camera-beyond-any-camera", "simulate --out {lab}/new --camera-fps 1e6", ("--camera-fps", "from 1 to 10000")),
    # simulate: every number in range, their product days of work
    ("simulate-film-that-cannot-finish", "simulate --out {lab}/new --duration 3600 --camera-fps 10000", ("about 24.6 hours", "24 hours")),
    # plan: the pendulum it simulates
    ("plan-period-too-short", "plan --display-hz 60 --camera-fps 120 --period-s 1e-9", ("--period-s", "from 0.2 to 20")),
    ("plan-display-beyond-any-display", "plan --display-hz 1e9 --camera-fps 120", ("--display-hz", "from 1 to 1000", "1e9")),
    ("plan-amplitude-out-of-range", "plan --display-hz 60 --camera-fps 120 --amplitude-deg 90", ("--amplitude-deg", "at most 45")),
    # bench: each option within a lab's reach, a batch within a day
    ("bench-predictors-duration-beyond-ten-minutes", "bench predictors --duration 1e12", ("--duration", "from 1 to 600", "1e12")),
    ("bench-predictors-horizon-beyond-a-second", "bench predictors --horizons-ms 10,5000", ("--horizons-ms", "from 0 to 1000")),
    ("bench-predictors-negative-seed", "bench predictors --seed=-3", ("--seed", "from 0 to 1e+09")),
    ("bench-batch-videos-beyond-a-lab", "bench batch --videos 1000000000", ("--videos", "from 1 to 1000")),
    ("bench-batch-that-cannot-finish", "bench batch --videos 1000 --duration 3600 --rounds 100", ("about 1.53e+04 hours", "24 hours")),
    ("bench-trackers-duration-beyond-ten-minutes", "bench trackers --duration 1e12", ("--duration", "from 0.5 to 600")),
    ("bench-trackers-rate-beyond-any-tracker", "bench trackers --rate 1e9", ("--rate", "from 1 to 5000")),
    ("bench-trackers-rate-beyond-the-simulated-tracker", "bench trackers --rate 6000", ("--rate", "from 1 to 5000", "6000")),
    ("bench-renderers-grid-beyond-a-day", "bench renderers --spec {lab}/renderers-beyond-a-day.toml", ("about 42.7 hours at the least", "24 hours")),
    # predictor parameters: each within what a tracker and a motion can be, never an overflow
    ("simulate-kalman-noise-beyond-a-metre", "simulate --out {lab}/new --predictor kalman-cv:{lab}/noise-beyond-a-metre.json",
     ("position_noise", "from 1e-09 to 1", "1e+200")),
    ("simulate-kalman-jerk-beyond-any-motion", "simulate --out {lab}/new --predictor kalman-ca:jerk_noise=1e300", ("jerk_noise", "from 1e-06 to 1e+06")),
    ("simulate-orientation-noise-beyond-half-a-turn", "simulate --out {lab}/new --predictor kalman-cv:orientation_noise=7",
     ("orientation_noise", "from 1e-09 to 3.14159")),
    ("simulate-damping-beyond-any-rate", "simulate --out {lab}/new --predictor auto:angular_velocity_damping=1e9", ("angular_velocity_damping", "from 0 to 10000")),
    ("simulate-desp-interval-beyond-ten-seconds", "simulate --out {lab}/new --predictor desp:sample_interval=1e6", ("sample_interval", "at most 10")),
    ("simulate-auto-memory-beyond-an-hour", "simulate --out {lab}/new --predictor auto:memory=1e9", ("memory", "from 0.001 to 3600")),
    ("simulate-adaptive-prior-beyond-an-hour", "simulate --out {lab}/new --predictor adaptive:gain_prior=1e9", ("gain_prior", "at most 3600")),
    ("simulate-slerp-interval-beyond-a-second", "simulate --out {lab}/new --predictor slerp:min_interval=5", ("min_interval", "at most 1")),
    ("simulate-gap-beyond-a-day", "simulate --out {lab}/new --predictor kalman-cv:max_gap=1e9", ("max_gap", "at most 86400")),
    ("bench-predictors-noise-beyond-a-metre", "bench predictors --predictor kalman-cv:position_noise=1e200", ("position_noise", "from 1e-09 to 1")),
    ("tune-acceleration-noise-beyond-any-motion", "tune kalman-cv:acceleration_noise=1e100 --trace {lab}/sorted.csv --horizon-ms 20 --out {lab}/p.json",
     ("acceleration_noise", "from 1e-06 to 10000")),
    # the tracker emulator: a tracker a lab could have
    ("emulate-tracker-rate-beyond-the-simulated-tracker", "emulate-tracker serial --tcp 0 --rate 1e9", ("--rate", "from 1 to 5000", "1e9")),
    ("emulate-tracker-duration-beyond-a-day", "emulate-tracker serial --tcp 0 --duration 1e12", ("--duration", "at most 86400")),
    ("emulate-tracker-noise-beyond-ten-centimetres", "emulate-tracker serial --tcp 0 --noise-mm 1e9", ("--noise-mm", "from 0 to 100")),
    ("emulate-tracker-orientation-noise-beyond-ten-degrees", "emulate-tracker lsl --name rig-test --noise-deg 90", ("--noise-deg", "from 0 to 10")),
    ("emulate-tracker-delay-beyond-a-second", "emulate-tracker serial --tcp 0 --delay-ms 5000", ("--delay-ms", "from 0 to 1000")),
    ("emulate-tracker-jitter-beyond-a-tenth", "emulate-tracker serial --tcp 0 --jitter-ms 1e6", ("--jitter-ms", "from 0 to 100")),
    ("emulate-tracker-dropout-beyond-all", "emulate-tracker lsl --name rig-test --dropout 1.5", ("--dropout", "below 1")),
    ("emulate-tracker-negative-seed", "emulate-tracker serial --tcp 0 --seed=-1", ("--seed", "from 0 to 1e+09")),
    ("emulate-tracker-drift-beyond-any-crystal", "emulate-tracker serial --tcp 0 --drift-ppm 1e9", ("--drift-ppm", "from -1000 to 1000")),
    ("emulate-tracker-port-beyond-tcp", "emulate-tracker serial --tcp 99999", ("--tcp 99999", "0 to 65535")),
    # live runs and recordings: at most a day
    ("measure-duration-beyond-a-day", "measure --tracker serial:loop:// --camera camera:0 --out {lab}/new --duration 1e9", ("--duration", "at most 86400")),
    ("measure-self-test-of-no-time", "measure --self-test --duration 0", ("--duration", "at most 86400", "got 0")),
    ("record-duration-beyond-a-day", "record --camera camera:0 --out {lab}/new --duration 1e12", ("--duration", "at most 86400")),
    ("record-tracker-duration-beyond-a-day", "record-tracker --tracker serial:loop:// --out {lab}/new --duration 1e9", ("--duration", "at most 86400")),
    ("board-record-duration-beyond-a-day", "board record --port loop:// --out {lab}/new --duration 1e9", ("--duration", "at most 86400")),
    # flashing lights: what an LED or a display can flash
    ("calibrate-camera-flash-beyond-ten-kilohertz", "calibrate-camera {lab}/a-file --flash-hz 1e9", ("--flash-hz", "at most 10000")),
    ("simulate-flash-of-no-frequency", "simulate --out {lab}/new --flash-hz 0", ("--flash-hz", "at most 10000", "got 0")),
    ("simulate-flash-display-of-one-refresh", "simulate --out {lab}/new --flash-display 1", ("--flash-display", "from 2 to 1000")),
    ("simulate-flash-always-on", "simulate --out {lab}/new --flash-hz 30 --flash-duty 1", ("--flash-duty", "below 1")),
    # the board: what its protocol carries and a lab's day holds
    ("board-sync-too-few-round-trips", "board sync --port loop:// --round-trips 2", ("--round-trips", "from 4 to 10000")),
    ("board-sync-series-beyond-a-day", "board sync --port loop:// --repeat 100000 --every 3600", ("about 1e+05 hours", "24 hours")),
    ("board-blink-code-of-no-bits", "board blink --port loop:// --bits 0", ("--bits", "from 1 to 4096")),
    ("board-blink-beyond-the-led", "board blink --port loop:// --level 256", ("--level", "from 1 to 255")),
    ("board-blink-seed-beyond-sixteen-bits", "board blink --port loop:// --seed 70000", ("--seed", "from 1 to 65535")),
    ("board-record-threshold-of-nothing", "board record --port loop:// --out {lab}/new --duration 5 --rise 0", ("--rise", "from 1 to 65535")),
    ("board-record-resync-beyond-an-hour", "board record --port loop:// --out {lab}/new --duration 5 --resync-every 1e9", ("--resync-every", "from 0.1 to 3600")),
    ("board-record-encoder-beyond-any-encoder", "board record --port loop:// --out {lab}/new --duration 5 --encoder-rate 1e9", ("--encoder-rate", "from 0 to 100000")),
    # listening, executors and benches: within a machine's reach
    ("devices-listening-beyond-ten-minutes", "devices --lsl-wait 1e9", ("--lsl-wait", "from 0 to 600")),
    ("sweep-workers-beyond-any-machine", "sweep {lab}/base-a-number.toml --out {lab}/sweep --workers 100000", ("--workers", "1 to 256")),
    ("bench-live-duration-beyond-a-day", "bench live --duration 1e9", ("--duration", "at most 86400")),
    ("bench-renderers-server-beyond-a-second", "bench renderers --server-ms 1e9", ("--server-ms", "at most 1000")),
    ("bench-seed-table-load-beyond-any-gpu", "bench renderers --seed-table --max-triangles 1e12", ("--max-triangles", "from 1 to 1e+08")),
    ("bench-seed-table-frame-beyond-ten-minutes", "bench renderers --seed-table --max-frame-s 1e6", ("--max-frame-s", "at most 600")),
    # plan: an accuracy a camera can reach and a latency needs
    ("plan-accuracy-beyond-any-camera", "plan --display-hz 60 --camera-fps 120 --accuracy-ms 1e-9", ("--accuracy-ms", "from 0.01 to 100")),
    ("plan-accuracy-of-no-use", "plan --display-hz 60 --camera-fps 120 --accuracy-ms 1e6", ("--accuracy-ms", "from 0.01 to 100")),
    # traces: scored only where a prediction can land on the truth, in time order
    ("bench-predictors-two-sample-trace", "bench predictors --trace {lab}/two-samples.csv", ("'two-samples'", "at least 10 samples")),
    ("bench-predictors-unsorted-trace", "bench predictors --trace {lab}/unsorted.csv", ("not in time order", "--repair")),
    # sweep and bench specs: a table where a table belongs, a grid counted before it is made
    ("sweep-base-a-number", "sweep {lab}/base-a-number.toml --out {lab}/sweep", ("base must be a table", "5")),
    ("sweep-grid-a-number", "sweep {lab}/grid-a-number.toml --out {lab}/sweep", ("grid must be a table", "5")),
    ("sweep-analysis-a-number", "sweep {lab}/analysis-a-number.toml --out {lab}/sweep", ("analysis must be a table", "3")),
    ("sweep-camera-a-number", "sweep {lab}/camera-a-number.toml --out {lab}/sweep", ("camera must be a table", "5")),
    ("sweep-billion-points", "sweep {lab}/billion-points.toml --out {lab}/sweep", ("1000000000 points", "1000 x 1000 x 1000", "10000")),
    ("bench-analyser-base-a-number", "bench analyser --spec {lab}/base-a-number.toml", ("base must be a table",)),
    ("bench-renderers-camera-a-number", "bench renderers --spec {lab}/renderers-camera-a-number.toml", ("latency_camera must be a table", "5")),
    # summaries and truths: the shape the rig writes
    ("report-summary-a-list", "report {lab}/summary-a-list.json --out {lab}/r.html", ('"rows" is a list',)),
    ("report-summary-rows-a-number", "report {lab}/summary-rows-a-number.json --out {lab}/r.html", ('"rows" is a list',)),
    ("report-summary-rows-of-numbers", "report {lab}/summary-rows-of-numbers.json --out {lab}/r.html", ("video column",)),
    ("report-summary-latency-a-table", "report {lab}/summary-latency-a-table.json --out {lab}/r.html", ("summary-latency-a-table.json",)),
    ("report-truncated-truth", "report {lab}/truncated-truth --out {lab}/r.html", ("truth.json", "simulate the run again")),
    ("report-truth-of-another-shape", "report {lab}/truth-of-another-shape --out {lab}/r.html", ("latency_ms (a number)",)),
    ("tune-horizon-beyond-a-second", "tune kalman-cv --trace {lab}/unsorted.csv --horizon-ms 1e12 --out {lab}/p.json", ("--horizon-ms", "from 0 to 1000")),
    ("tune-iterations-beyond-any-fit", "tune kalman-cv --trace {lab}/unsorted.csv --horizon-ms 20 --max-iterations 1e12 --out {lab}/p.json",
     ("--max-iterations", "from 0 to 10000")),
    ("tune-two-sample-trace", "tune kalman-cv --trace {lab}/two-samples.csv --horizon-ms 20 --out {lab}/p.json", ("at least 10 samples",)),
]


@pytest.mark.parametrize("argv, words", [pytest.param(argv, words, id=name) for name, argv, words in CASES])
def test_out_of_bounds_is_one_line_before_any_work(
    run_rig: Callable[..., tuple[int, str, str]],
    snapshot: Callable[[Path], dict[Path, str]],
    assert_one_line_error: Callable[..., None],
    argv: str,
    words: tuple[str, ...],
    lab: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    before = snapshot(lab)
    code, _, err = run_rig(argv.format(lab=lab).split(), capsys)
    assert_one_line_error(code, err, *words)
    assert snapshot(lab) == before
    assert not (lab / "new").exists()


SHORT_FILM = "[base]\nduration_s = 0.5\ncamera.fps = 60.0\ncamera.width = 160\ncamera.height = 120\ncamera.subsamples = 1\n"
"""Half a pendulum period, filmed small: simulated in a moment, refused by the analyser (too few periods)."""


def _assert_every_one_failed(code: int, err: str, what: str) -> None:
    """Exit status 2, and the last line of stderr says every one of `what` failed."""
    assert "Traceback" not in err
    assert code == EXIT_USER_ERROR, err
    assert f"every one of the {what}" in err.strip().splitlines()[-1], err


def test_a_sweep_whose_every_point_failed_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    spec = tmp_path / "short.toml"
    spec.write_text(SHORT_FILM + "[grid]\nseed = [1, 2]\n")
    code, _, err = run_rig(["sweep", str(spec), "--out", str(tmp_path / "sweep")], capsys)
    _assert_every_one_failed(code, err, "2 points failed")
    assert "pendulum periods" in err
    assert (tmp_path / "sweep" / "summary.csv").exists()


def test_a_sweep_point_whose_film_is_too_short_is_a_failed_row_and_the_sweep_goes_on(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    spec = tmp_path / "short.toml"
    spec.write_text(SHORT_FILM + "[[points]]\ncamera.impairments.every_nth = 2\n\n[[points]]\nseed = 2\n")
    code, _, err = run_rig(["sweep", str(spec), "--out", str(tmp_path / "sweep")], capsys)
    _assert_every_one_failed(code, err, "2 points failed")
    rows = json.loads((tmp_path / "sweep" / "summary.json").read_text())["rows"]
    assert [row["status"] for row in rows] == ["failed", "failed"]
    assert rows[0]["error"].startswith("not simulated: the film would hold 15 frames") and "at least 24" in rows[0]["error"]
    assert "pendulum periods" in rows[1]["error"]
    assert not (tmp_path / "sweep" / "point000").exists() and (tmp_path / "sweep" / "point001" / "video.avi").exists()


def test_a_bench_whose_every_case_was_refused_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    spec = tmp_path / "short.toml"
    spec.write_text(SHORT_FILM + '[[points]]\nlabels = { case = "short", group = "mixed", impairment = "none" }\nseed = 1\n')
    code, _, err = run_rig(["bench", "analyser", "--spec", str(spec)], capsys)
    _assert_every_one_failed(code, err, "1 cases")


def test_a_batch_whose_every_video_failed_exits_2(
    run_rig: Callable[..., tuple[int, str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str],
) -> None:
    for name in ("black.avi", "grey.avi"):
        writer = cv2.VideoWriter(str(tmp_path / name), cv2.VideoWriter_fourcc(*"MJPG"), 60.0, (64, 48))
        for _ in range(40):
            writer.write(np.full((48, 64, 3), 0 if name == "black.avi" else 128, np.uint8))
        writer.release()
    code, _, err = run_rig(["analyse", str(tmp_path / "black.avi"), str(tmp_path / "grey.avi")], capsys)
    _assert_every_one_failed(code, err, "2 videos failed")
