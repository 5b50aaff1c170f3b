"""Live camera capture with OpenCV, against a file and a tcp:// Motion-JPEG stream (this OpenCV
has FFmpeg but no video devices), and the film a run writes of it: every frame with its time,
dropped frames found and filled, settings a camera refuses reported, an unplugged camera ending
cleanly with its fault."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from rig.clock import MonotonicClock
from rig.devices.camera.opencv_camera import apply_settings, opencv_camera, parse_camera_address
from rig.devices.camera.opencv_camera import CameraSettings
from rig.devices.protocols import CameraFrame
from rig.errors import ConfigError, RigError
from rig.writers import VideoRecord
from rig.session.run_record import FilmRecord

FPS = 50.0
FRAMES = 40


def _frames(count: int) -> list[np.ndarray]:
    return [np.full((48, 64), 5 * i % 250, dtype=np.uint8) for i in range(count)]


def _wait(condition, timeout_s: float = 20.0) -> None:
    end = time.monotonic() + timeout_s
    while not condition() and time.monotonic() < end:
        time.sleep(0.02)


def test_a_camera_spec_keeps_the_stream_options_and_takes_the_rigs() -> None:
    source, settings = parse_camera_address("rtsp://cam/live?token=x&fps=120&size=640x480&fourcc=MJPG&exposure=-7")
    assert (source.kind, source.address) == ("stream", "rtsp://cam/live?token=x")
    assert settings == CameraSettings(120.0, (640, 480), -7.0, "MJPG")
    assert parse_camera_address("0")[0].kind == "device"
    with pytest.raises(ConfigError, match="WIDTHxHEIGHT"):
        parse_camera_address("0?size=640")


def _black(i: int, t: float, t_slot: float | None = None) -> CameraFrame:
    return CameraFrame(i, t, 1.0 / FPS, np.zeros((48, 64), dtype=np.uint8), t_slot=t_slot)


def test_dropped_frames_are_found_from_the_times_and_filled_to_keep_the_timing(tmp_path: Path) -> None:
    writer = FilmRecord(tmp_path, FPS, 64, 48)
    times = [i / FPS for i in range(10)] + [i / FPS for i in range(13, 20)]
    for i, t in enumerate(times):
        writer.write(_black(i, t))
    writer.close()
    assert writer.dropped == 3 and writer.frames == 20
    assert writer.measured_fps() == pytest.approx(FPS)
    rows = (tmp_path / "camera_frames.csv").read_text().splitlines()[1:]
    assert [int(row.split(",")[-1]) for row in rows].count(1) == 3


class RefusingCapture:
    """A capture that takes every setting but the frame rate (it stays at 30)."""

    def __init__(self) -> None:
        self.values = {cv2.CAP_PROP_FPS: 30.0, cv2.CAP_PROP_FRAME_WIDTH: 320.0, cv2.CAP_PROP_FRAME_HEIGHT: 240.0,
                       cv2.CAP_PROP_EXPOSURE: 0.0, cv2.CAP_PROP_FOURCC: 0.0}  # fmt: skip

    def set(self, prop: int, value: float) -> bool:
        if prop != cv2.CAP_PROP_FPS:
            self.values[prop] = float(value)
        return True

    def get(self, prop: int) -> float:
        return self.values.get(prop, 0.0)


def test_a_camera_that_knows_its_schedule_finds_drops_from_it_whatever_its_jitter(tmp_path: Path) -> None:
    writer = FilmRecord(tmp_path, FPS, 64, 48)
    slots = [i for i in range(30) if i not in (7, 8, 20)]
    jitter = np.random.default_rng(3).uniform(-0.45, 0.45, len(slots)) / FPS
    for i, (slot, late) in enumerate(zip(slots, jitter)):
        writer.write(_black(i, slot / FPS + late, slot / FPS))
    writer.close()
    assert (writer.dropped, writer.frames) == (3, 30)
    assert writer.measured_fps() == pytest.approx(FPS)


def test_a_setting_the_camera_refuses_is_reported_not_accepted() -> None:
    check = apply_settings(RefusingCapture(), CameraSettings(fps=240.0, size=(640, 480), fourcc="MJPG"), "device")
    assert check.refused == ["fps 240.0 (the camera reports 30.0)"]
    assert check.reported["size"] == (640, 480) and check.reported["fourcc"] == "MJPG"


def test_a_file_camera_hands_over_every_frame_with_its_time(tmp_path: Path) -> None:
    with VideoRecord(tmp_path / "in.avi", FPS, 64, 48) as video:
        for frame in _frames(FRAMES):
            video.write(frame)
    camera = opencv_camera(str(tmp_path / "in.avi"))
    camera.connect(MonotonicClock())
    _wait(lambda: camera.finished)
    camera.close()
    frames = camera.poll()
    assert [frame.index for frame in frames] == list(range(FRAMES))
    np.testing.assert_allclose(np.diff([frame.t_start for frame in frames]), 1.0 / FPS)
    np.testing.assert_allclose([frame.image.mean() for frame in frames], [5 * i % 250 for i in range(FRAMES)], atol=2.0)
    assert (camera.report()["captured"], camera.fault()) == (FRAMES, None)


def test_settings_asked_of_a_file_are_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="its own"):
        apply_settings(RefusingCapture(), CameraSettings(fps=60.0), "file")


def _serve_mjpeg(frames: list[np.ndarray], listener: socket.socket, stop_after: int) -> None:
    client, _ = listener.accept()
    with client:
        for i, frame in enumerate(frames[:stop_after]):
            client.sendall(cv2.imencode(".jpg", frame)[1].tobytes())
            time.sleep(1.0 / FPS)


@pytest.mark.slow
def test_a_tcp_mjpeg_stream_is_captured_and_its_end_ends_the_capture_cleanly(tmp_path: Path) -> None:
    listener = socket.create_server(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    sent = 3 * FRAMES
    server = threading.Thread(target=_serve_mjpeg, args=(_frames(sent), listener, sent))
    server.start()
    camera = opencv_camera(f"tcp://127.0.0.1:{port}")
    film = None
    try:
        camera.connect(MonotonicClock())
        film = FilmRecord(tmp_path, camera.fps, camera.width, camera.height)
        deadline = time.monotonic() + 30.0
        while camera.fault() is None and time.monotonic() < deadline:
            for frame in camera.poll():
                film.write(frame)
            time.sleep(0.02)
        assert "stopped delivering frames" in camera.fault().reason
        for frame in camera.poll():
            film.write(frame)
    finally:
        camera.close()
        if film is not None:
            film.close()
        server.join()
        listener.close()
    report = film.report()
    # FFmpeg keeps what it read while probing the stream: every frame sent reaches the video.
    assert report["frames"] - report["dropped"] == sent == camera.report()["captured"]
    assert int(cv2.VideoCapture(str(tmp_path / "video.avi")).get(cv2.CAP_PROP_FRAME_COUNT)) == report["frames"]


def test_a_missing_camera_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(RigError, match="no video file"):
        opencv_camera(str(tmp_path / "absent.avi")).connect(MonotonicClock())
