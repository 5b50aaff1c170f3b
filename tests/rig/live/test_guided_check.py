"""The guided mode's check of the first seconds: a video of two swinging blobs passes; a
saturated one and one with nothing moving are each told what to fix."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rig.live.camera_recording import check_first_seconds
from rig.writers import VideoRecord

FPS = 60.0


def _video(path: Path, frame) -> Path:
    with VideoRecord(path, FPS, 160, 120) as video:
        for i in range(int(2 * FPS)):
            video.write(frame(i / FPS))
    return path


def _blobs(t: float, level: int = 200, background: int = 8) -> np.ndarray:
    image = np.full((120, 160), background, dtype=np.uint8)
    for centre in (40, 120):
        x = int(centre + 25 * np.sin(2 * np.pi * t))
        image[55:65, x - 5 : x + 5] = level
    return image


def test_two_swinging_blobs_pass(tmp_path: Path) -> None:
    assert check_first_seconds(_video(tmp_path / "good.avi", _blobs)) == []


def test_a_saturated_exposure_is_told_to_shorten(tmp_path: Path) -> None:
    problems = check_first_seconds(_video(tmp_path / "bright.avi", lambda t: _blobs(t, 255, 255)))
    assert any("saturated" in problem for problem in problems)


def test_nothing_moving_is_told_to_check_the_bench(tmp_path: Path) -> None:
    problems = check_first_seconds(_video(tmp_path / "still.avi", lambda t: _blobs(0.0)))
    assert any("two moving bright blobs" in problem for problem in problems)
