"""Films the rig cannot write whole, or that hold too few frames to analyse, are refused before the
run: one line on stderr naming the limit, exit status 2, and no output folder made."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rig.cli import EXIT_USER_ERROR, main
from rig.service.simulate import MIN_FILM_FRAMES
from rig.writers import MJPEG_AVI_MAX_FPS, avi_frame_count


def _refusal(tmp_path: Path, capsys: pytest.CaptureFixture[str], *options: str) -> str:
    out = tmp_path / "run"
    assert main(["simulate", "--out", str(out), "--duration", "0.5", *options]) == EXIT_USER_ERROR
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert not out.exists()
    return err


@pytest.mark.parametrize("fps", ["1001", "2000", "4000"])
def test_an_avi_film_faster_than_it_holds_is_refused_naming_the_fastest(tmp_path: Path, capsys: pytest.CaptureFixture[str], fps: str) -> None:
    err = _refusal(tmp_path, capsys, "--camera-fps", fps)
    assert f"at most {MJPEG_AVI_MAX_FPS:g} frames a second, not {fps}" in err and "--container mp4" in err


def test_a_decimated_avi_film_is_judged_by_the_rate_it_is_written_at(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "--out", str(tmp_path / "run"), "--duration", "0.5", "--camera-fps", "2000", "--every-nth", "2", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["camera_fps"] == MJPEG_AVI_MAX_FPS
    assert avi_frame_count(Path(summary["video"])) == summary["frames"] == 500  # every other one of the sensor's 999 exposures


@pytest.mark.parametrize("every_nth", ["1000", "6"])
def test_a_film_too_short_to_analyse_is_refused_naming_the_minimum(tmp_path: Path, capsys: pytest.CaptureFixture[str], every_nth: str) -> None:
    err = _refusal(tmp_path, capsys, "--every-nth", every_nth)
    assert f"needs at least {MIN_FILM_FRAMES}" in err and "--every-nth" in err


def test_a_flashing_lights_film_too_short_for_the_shutter_estimate_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _refusal(tmp_path, capsys, "--camera-fps", "60", "--flash-hz", "7")
    assert "needs at least 40" in err
