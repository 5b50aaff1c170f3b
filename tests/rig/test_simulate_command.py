"""`rig simulate --release-s S --board`: a lab's run from the command line, and its bad options."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from analysis.board.recording import load_table
from rig.cli import main


def test_a_held_release_and_a_board_from_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["simulate", "--out", str(tmp_path), "--duration", "4", "--camera-fps", "60", "--release-s", "2.5", "--board", "--json"])
    assert code == 0
    assert json.loads(capsys.readouterr().out)["frames"] == 239
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert truth["board"]["release_s"] == 2.5
    assert truth["board"]["blink"]["bits"] == 64
    assert truth["config"]["pendulum"]["release_s"] == 2.5
    encoder = load_table(tmp_path / "board", "encoder.csv")
    assert encoder["rig_time_s"].min() > 2.5
    led = load_table(tmp_path / "board", "led.csv")
    np.testing.assert_allclose(led["board_time_s"] - led["rig_time_s"], truth["board"]["offset_s"], atol=1e-6)
    assert (tmp_path / "board" / "recording.json").exists()


def test_help_explains_the_lab_options(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    text = capsys.readouterr().out
    assert "--release-s S" in text and "--board" in text and "blink" in text


@pytest.mark.parametrize(
    "arguments, message",
    [
        (["--duration", "3", "--release-s", "2.5"], "release at 2.5 s must fall within the filmed span"),
        (["--duration", "2", "--board"], "must fall within the filmed span"),
    ],
)
def test_a_release_or_blink_the_film_cannot_hold_is_a_one_line_error(
    arguments: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["simulate", "--out", str(tmp_path / "x"), *arguments]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert message in err
    assert not (tmp_path / "x").exists()


def test_a_negative_release_is_rejected_by_the_parser(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "--out", str(tmp_path / "x"), "--release-s", "-1"])
    assert exit_.value.code == 2
    assert "--release-s" in capsys.readouterr().err


def test_the_cameras_impairments_are_options_and_reach_truth_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    options = ["--camera-fps", "120", "--every-nth", "2", "--first-frame", "1", "--mirrored", "--blur-px", "1.5", "--noise-dn", "4",
               "--dim-led", "0.5", "--occluded", "led", "--missing-fraction", "0.1", "--bright-object-dn", "300"]  # fmt: skip
    assert main(["simulate", "--out", str(tmp_path), "--duration", "2", *options, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    truth = json.loads((tmp_path / "truth.json").read_text())
    camera = truth["config"]["camera"]
    assert camera["noise_dn"] == 4.0
    assert camera["impairments"] == {
        "blur_sigma_px": 1.5, "dim_led": 0.5, "mirrored": True, "bright_object_dn": 300.0, "occluded": "led",
        "missing_fraction": 0.1, "every_nth": 2, "first_frame": 1,
    }  # fmt: skip
    assert truth["camera_fps"] == 60.0 and summary["camera_fps"] == 60.0
    video = cv2.VideoCapture(str(tmp_path / "video.avi"))
    assert video.get(cv2.CAP_PROP_FPS) == pytest.approx(60.0)
    assert truth["frames"] == int(video.get(cv2.CAP_PROP_FRAME_COUNT)) == 119  # of the sensor's 239 exposures
    led_x, sphere_x = truth["led_roi"][0], truth["sphere_roi"][0]
    assert sphere_x < camera["width"] / 2 < led_x  # mirrored: the LED films on the right


def test_a_phone_like_film_from_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    options = ["--camera-fps", "60", "--exposure", "0.5", "--readout-ms", "8", "--frame-jitter-ms", "2", "--layout", "led-below",
               "--container", "mov", "--codec", "hevc"]  # fmt: skip
    assert main(["simulate", "--out", str(tmp_path), "--duration", "1", *options, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["video"].endswith("video.mov")
    truth = json.loads((tmp_path / "truth.json").read_text())
    camera = truth["config"]["camera"]
    assert (camera["readout_s"], camera["frame_jitter_s"], camera["container"], camera["codec"]) == (0.008, 0.002, "mov", "hevc")
    assert truth["config"]["layout"] == "led-below"
    film = truth["film"]
    assert film["readout_ms"] == 8.0 and film["frame_times"] == "frame_times.csv"
    assert film["led_row"] - film["sphere_row"] == pytest.approx(0.35, abs=0.02)
    rows = (tmp_path / "frame_times.csv").read_text().splitlines()
    assert rows[0] == "frame,t_start,pts,t_presented" and len(rows) == truth["frames"] + 1


def test_a_default_films_truth_holds_no_film_settings(tmp_path: Path) -> None:
    assert main(["simulate", "--out", str(tmp_path), "--duration", "0.5"]) == 0
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert "film" not in truth and "layout" not in truth["config"] and "readout_s" not in truth["config"]["camera"]
    assert not (tmp_path / "frame_times.csv").exists()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--frame-jitter-ms", "1", "--exposure", "0.5"], "mp4 or mov"),
        (["--readout-ms", "5"], "readout"),
        (["--container", "mp4", "--codec", "mjpeg"], "not written here"),
        (["--layout", "0.9,0.5,0.4/0.2,0.5,0.4"], "outside"),
    ],
)
def test_impossible_films_are_refused_with_exit_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], message: str) -> None:
    assert main(["simulate", "--out", str(tmp_path), "--duration", "0.5", *options]) == 2
    assert message in capsys.readouterr().err
