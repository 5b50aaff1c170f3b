"""`rig record` from a file camera keeps every frame at every rate a camera films: the film holds each
frame of the source, in order, at its time (an MJPEG AVI up to the 1000 fps it holds, H.264 in an MP4
above), its frame table lists exactly those frames, and a rate no film holds is refused before
anything is written."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Callable

import av
import cv2
import numpy as np
import pytest

from rig.film_file import FRAME_TIMES_FILE, STAMPED_MAX_FPS, TIME_BASE, StampedVideoRecord, film_holding, video_file_name
from rig.session.run_record import FRAMES_FILE
from rig.writers import MJPEG_AVI_MAX_FPS, VideoRecord

BAR_STEP = 5
"""Pixels the source's bright bar moves each frame: neighbouring frames differ everywhere it passes."""


def _pattern(index: int, size: tuple[int, int]) -> np.ndarray:
    """Frame `index` of the source: a bar at a place and brightness its index sets, on a dark ground."""
    width, height = size
    grey = np.full((height, width), 16, np.uint8)
    left = (index * BAR_STEP) % (width - 8)
    grey[height // 6 : height - height // 6, left : left + 8] = 180 + (index % 5) * 15
    return grey


def _source(folder: Path, fps: float, frames: int, size: tuple[int, int]) -> Path:
    """A film of `frames` pattern frames at `fps`, in the film the rig writes at that rate."""
    container, codec = film_holding(fps)
    path = folder / f"source.{container}"
    writer = VideoRecord(path, fps, *size) if container == "avi" else StampedVideoRecord(path, container, codec, fps, *size)
    with writer:
        for index in range(frames):
            writer.write(_pattern(index, size), index / fps)
    return path


def _decoded(path: Path) -> list[np.ndarray]:
    capture = cv2.VideoCapture(str(path))
    frames = []
    while (read := capture.read())[0]:
        frames.append(cv2.cvtColor(read[1], cv2.COLOR_BGR2GRAY).astype(np.float64))
    capture.release()
    return frames


def _stamps(path: Path) -> list[int]:
    with av.open(str(path)) as film:
        return sorted(int(packet.pts) for packet in film.demux(film.streams.video[0]) if packet.pts is not None)


def _record_and_check(fps: float, frames: int, size: tuple[int, int], tmp_path: Path, run_rig: Callable[..., tuple[int, str, str]],
                      capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    source = _source(tmp_path, fps, frames, size)
    out = tmp_path / "film"
    code, _, err = run_rig(["record", "--camera", f"camera:{source}", "--duration", str(frames / fps + 30.0), "--out", str(out)], capsys)
    assert code == 0, err
    assert err.strip() == "" or "recording" in err
    container = film_holding(fps)[0]
    video = out / video_file_name(container)
    recorded = _decoded(video)
    assert len(recorded) == frames
    for index, image in enumerate(recorded):
        errors = {k: float(np.mean(np.abs(image - _pattern(k, size)))) for k in (index - 1, index, index + 1) if 0 <= k < frames}
        assert errors[index] < 3.0 and min(errors, key=errors.get) == index, (index, errors)
    with open(out / FRAMES_FILE, newline="") as table:
        rows = list(csv.DictReader(table))
    assert [int(row["frame"]) for row in rows] == list(range(frames))
    assert all(row["filled"] == "0" for row in rows)
    report = json.loads((out / "camera.json").read_text())
    assert report["fps"] == pytest.approx(fps, rel=1e-3)  # as the source states it: a stamped film's ticks round its rate
    starts = np.array([float(row["t_capture"]) for row in rows])
    np.testing.assert_allclose(starts - starts[0], np.arange(frames) / report["fps"], rtol=0, atol=1e-9)
    assert (report["video"], report["frames"], report["dropped"], report["partial"]) == (video.name, frames, 0, False)
    if container == "avi":
        assert not (out / FRAME_TIMES_FILE).exists()
        return
    with open(out / FRAME_TIMES_FILE, newline="") as table:
        listed = [int(row["pts"]) for row in csv.DictReader(table)]
    true_ticks = np.arange(frames) / fps / float(TIME_BASE)
    assert np.all(np.abs(np.array(listed) - true_ticks) <= 1.0)  # each frame within a tick of its true time
    assert _stamps(video) == listed


@pytest.mark.parametrize("fps", [30.0, MJPEG_AVI_MAX_FPS, MJPEG_AVI_MAX_FPS + 1.0, 4000.0], ids=lambda fps: f"{fps:g}fps")
def test_record_keeps_every_frame_in_order_at_its_time(
    fps: float, tmp_path: Path, run_rig: Callable[..., tuple[int, str, str]], capsys: pytest.CaptureFixture[str]
) -> None:
    _record_and_check(fps, max(24, int(fps / 10)), (64, 48), tmp_path, run_rig, capsys)


@pytest.mark.slow
@pytest.mark.parametrize("fps", [30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1000.0, 1001.0, 2000.0, 3000.0, 4000.0, STAMPED_MAX_FPS],
                         ids=lambda fps: f"{fps:g}fps")  # fmt: skip
def test_record_keeps_every_frame_of_a_second_at_camera_sizes(
    fps: float, tmp_path: Path, run_rig: Callable[..., tuple[int, str, str]], capsys: pytest.CaptureFixture[str]
) -> None:
    _record_and_check(fps, int(fps), (320, 240), tmp_path, run_rig, capsys)


def test_a_camera_faster_than_any_film_is_refused_before_anything_is_written(
    tmp_path: Path, run_rig: Callable[..., tuple[int, str, str]], snapshot: Callable[[Path], dict[Path, str]],
    assert_one_line_error: Callable[..., None], capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    fps = 2 * STAMPED_MAX_FPS
    source = tmp_path / "source.mp4"
    with StampedVideoRecord(source, "mp4", "h264", fps, 64, 48) as writer:
        for index in range(24):
            writer.write(_pattern(index, (64, 48)), index / fps)
    before = snapshot(tmp_path)
    code, _, err = run_rig(["record", "--camera", f"camera:{source}", "--duration", "1", "--out", str(tmp_path / "film")], capsys)
    assert_one_line_error(code, err, f"at most {STAMPED_MAX_FPS:g} frames a second, not {fps:g}")
    assert snapshot(tmp_path) == before and not (tmp_path / "film").exists()
