"""Films as phones write them (H.264 and HEVC in MP4 and MOV, each frame with its own presentation
time): the frame times read back are the ones written, and only whole frames repeat."""

import csv
from fractions import Fraction
from pathlib import Path

import av
import numpy as np
import pytest

from analysis.options import AnalysisOptions
from analysis.tracks import track
from analysis.video.file import VideoFile
from rig.film_file import FRAME_TIMES_FILE, TIME_BASE, StampedVideoRecord

FPS = 60.0


def _write(path: Path, frames: np.ndarray, starts: np.ndarray, container: str, codec: str) -> Path:
    with StampedVideoRecord(path, container, codec, FPS, frames.shape[2], frames.shape[1]) as video:
        for frame, start in zip(frames, starts, strict=True):
            video.write(frame, float(start))
    return path


def _written_times(folder: Path) -> dict[str, np.ndarray]:
    with open(folder / FRAME_TIMES_FILE, newline="") as file:
        rows = list(csv.DictReader(file))
    return {name: np.array([float(row[name]) for row in rows]) for name in rows[0]}


@pytest.mark.parametrize(("container", "codec"), [("mp4", "h264"), ("mov", "hevc")])
def test_variable_frame_times_read_back_as_written(tmp_path: Path, container: str, codec: str, scene, render_video) -> None:
    frames = render_video(scene(fps=FPS, duration_s=1.0))
    rng = np.random.default_rng(1)
    starts = np.arange(len(frames)) / FPS + np.r_[0.0, rng.uniform(-3e-3, 3e-3, len(frames) - 1)]
    path = _write(tmp_path / f"film.{container}", frames, starts, container, codec)
    written = _written_times(tmp_path)
    np.testing.assert_array_equal(written["pts"], np.rint((starts - starts[0]) / float(TIME_BASE)))
    stamps, decoded = zip(*VideoFile(path).frames(), strict=True)
    np.testing.assert_array_equal(np.array(stamps), written["t_presented"])
    np.testing.assert_array_equal(np.rint(np.array(stamps) / float(TIME_BASE)), written["pts"])
    # full-range grey comes back unscaled, at a phone-like quality (the sensor noise, 2 levels, smoothed)
    error = np.stack(decoded).astype(float) - frames
    assert abs(error.mean()) < 0.3 and np.abs(error).mean() < 2.5


def test_a_still_region_of_an_hevc_film_is_no_repeated_frame(tmp_path: Path, scene, render_video) -> None:
    """The pendulum stops: both blobs' regions come out of the encoder bit for bit the same in many
    frames, while a counter in the corner changes every frame. No frame repeats whole."""
    clip = scene(fps=FPS, duration_s=6.3, stop_s=3.0)
    frames = render_video(clip).copy()
    frames[:, :4, :4] = (20 + np.arange(len(frames)) % 200)[:, None, None]
    path = _write(tmp_path / "film.mp4", frames, np.arange(len(frames)) / FPS, "mp4", "hevc")
    tracks = track(path, AnalysisOptions(led_side="left"))
    still = [np.diff(t.x) == 0 for t in (tracks.led, tracks.sphere)]
    assert np.count_nonzero(still[0] & still[1]) >= 3  # both regions identical to the frame before
    assert tracks.diagnostics["repeated_frames"] == 0
    assert not any("repeat" in warning for warning in tracks.warnings)


def _lossless_h264(path: Path, frames: np.ndarray) -> Path:
    with av.open(str(path), "w") as film:
        stream = film.add_stream("libx264", rate=Fraction(60), options={"qp": "0"})
        stream.width, stream.height, stream.pix_fmt = frames.shape[2], frames.shape[1], "yuv444p"
        for index, grey in enumerate(frames):
            frame = av.VideoFrame.from_ndarray(np.stack([grey, np.full_like(grey, 128), np.full_like(grey, 128)]), format="yuv444p")
            frame.pts, frame.time_base = index, Fraction(1, 60)
            for packet in stream.encode(frame):
                film.mux(packet)
        for packet in stream.encode(None):
            film.mux(packet)
    return path


@pytest.mark.parametrize("kind", ["mjpeg", "h264"])
def test_one_duplicated_frame_is_reported_once(tmp_path: Path, kind: str, scene, render_video, mjpg_file) -> None:
    clip = scene(fps=FPS, duration_s=6.3)
    frames = render_video(clip).copy()
    frames[201] = frames[200]
    path = mjpg_file(tmp_path / "film.avi", frames, FPS) if kind == "mjpeg" else _lossless_h264(tmp_path / "film.mp4", frames)
    tracks = track(path, AnalysisOptions(led_side="left"))
    assert tracks.diagnostics["repeated_frames"] == 1
    assert not tracks.led.valid[201] and not tracks.sphere.valid[201]
    assert tracks.led.valid[200] and tracks.led.valid[202]
