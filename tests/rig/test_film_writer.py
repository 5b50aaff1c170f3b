"""The film writers keep every frame written, in order, at the rate asked, or refuse before the
first frame; a frame the file cannot take raises RigError and leaves a readable film whose frame
table lists exactly the frames it holds."""

from __future__ import annotations

import csv
import errno
from pathlib import Path

import av
import cv2
import numpy as np
import pytest

from analysis import AnalysisOptions, analyse
from rig.devices.protocols import CameraFrame
from rig.errors import RigError
from rig.film_file import FRAME_TIMES_FILE, TIME_BASE, StampedVideoRecord
from rig.service import SimulationConfig, simulate
from rig.session.run_record import FRAMES_FILE, FilmRecord
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.writers import MJPEG_AVI_MAX_FPS, VideoRecord

WIDTH, HEIGHT = 64, 48
BITS = 12
SQUARE = 16
OPENCV_WRITER = cv2.VideoWriter


def numbered(index: int) -> np.ndarray:
    """A frame showing `index` in binary: one 16-pixel square per bit, white for 1."""
    image = np.zeros((HEIGHT, WIDTH), np.uint8)
    for bit in range(BITS):
        if index >> bit & 1:
            row, column = divmod(bit, WIDTH // SQUARE)
            image[row * SQUARE : (row + 1) * SQUARE, column * SQUARE : (column + 1) * SQUARE] = 255
    return image


def number_shown(grey: np.ndarray) -> int:
    """The index a `numbered` frame shows, read from the middle of each square."""
    columns = WIDTH // SQUARE
    return sum(1 << bit for bit in range(BITS) if grey[bit // columns * SQUARE + SQUARE // 2, bit % columns * SQUARE + SQUARE // 2] > 128)


def avi_numbers(path: Path) -> tuple[list[int], float, int]:
    """The numbers an AVI's frames show, its stated rate and its stated frame count."""
    capture = cv2.VideoCapture(str(path))
    try:
        numbers = []
        while True:
            ok, image = capture.read()
            if not ok:
                break
            numbers.append(number_shown(image[..., 0]))
        return numbers, capture.get(cv2.CAP_PROP_FPS), int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
    finally:
        capture.release()


@pytest.mark.parametrize("fps", [30.0, 59.94, 240.0, 719.3, 999.5, 1000.0])
def test_an_avi_holds_every_frame_in_order_at_the_rate_asked(tmp_path: Path, fps: float) -> None:
    count = 90
    with VideoRecord(tmp_path / "film.avi", fps, WIDTH, HEIGHT) as video:
        for index in range(count):
            video.write(numbered(index))
    numbers, stated_fps, stated_count = avi_numbers(tmp_path / "film.avi")
    assert numbers == list(range(count))
    assert stated_count == video.frames == count
    assert stated_fps == pytest.approx(fps, rel=1e-9)


@pytest.mark.parametrize("fps", [1000.5, 1001.0, 2000.0, 4000.0])
def test_an_avi_refuses_a_rate_it_cannot_hold_before_the_first_frame(tmp_path: Path, fps: float) -> None:
    with pytest.raises(RigError, match=f"at most {MJPEG_AVI_MAX_FPS:g} frames a second") as refusal:
        VideoRecord(tmp_path / "film.avi", fps, WIDTH, HEIGHT)
    assert len(str(refusal.value).splitlines()) == 1
    assert not (tmp_path / "film.avi").exists()


@pytest.mark.parametrize("fps", [30.0, 1000.0, 2000.0, 4000.0])
def test_a_stamped_film_holds_every_frame_in_order_at_rates_up_to_4000_fps(tmp_path: Path, fps: float) -> None:
    count = 60
    starts = np.arange(count) / fps
    with StampedVideoRecord(tmp_path / "film.mp4", "mp4", "h264", fps, WIDTH, HEIGHT) as video:
        for index, start in enumerate(starts):
            video.write(numbered(index), float(start))
    with av.open(str(tmp_path / "film.mp4")) as film:
        stream = film.streams.video[0]
        assert stream.frames == count
        decoded = [(number_shown(frame.to_ndarray(format="gray")), frame.pts) for frame in film.decode(stream)]
    assert [number for number, _ in decoded] == list(range(count))
    np.testing.assert_array_equal([pts for _, pts in decoded], np.rint(starts / float(TIME_BASE)))
    with open(tmp_path / FRAME_TIMES_FILE, newline="") as file:
        assert len(list(csv.DictReader(file))) == count


class FailingWriter:
    """An OpenCV video writer whose disk fills after `room` frames: later writes fail, as
    cv2.VideoWriter.write says, by returning False."""

    room = 5

    def __init__(self, *args: object) -> None:
        self._writer = OPENCV_WRITER(*args)
        self._written = 0

    def isOpened(self) -> bool:  # noqa: N802 - OpenCV's name
        return self._writer.isOpened()

    def set(self, *args: object) -> bool:
        return self._writer.set(*args)

    def write(self, image: np.ndarray) -> bool:
        if self._written >= self.room:
            return False
        self._written += 1
        return self._writer.write(image)

    def release(self) -> None:
        self._writer.release()


class DroppingWriter(FailingWriter):
    """A writer that says it wrote frames it never wrote (beyond `room`)."""

    def write(self, image: np.ndarray) -> bool:
        return super().write(image) or True


def test_a_write_that_fails_raises_and_leaves_a_readable_film_of_the_frames_before_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cv2, "VideoWriter", FailingWriter)
    video = VideoRecord(tmp_path / "film.avi", 240.0, WIDTH, HEIGHT)
    with video:
        for index in range(FailingWriter.room):
            video.write(numbered(index))
        with pytest.raises(RigError, match=f"holds the {FailingWriter.room} before it"):
            video.write(numbered(FailingWriter.room))
    assert video.frames == FailingWriter.room
    numbers, _, stated_count = avi_numbers(tmp_path / "film.avi")
    assert numbers == list(range(FailingWriter.room)) and stated_count == FailingWriter.room


def test_a_film_missing_frames_when_closed_raises(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cv2, "VideoWriter", DroppingWriter)
    video = VideoRecord(tmp_path / "film.avi", 240.0, WIDTH, HEIGHT)
    for index in range(FailingWriter.room + 3):
        video.write(numbered(index))
    with pytest.raises(RigError, match=f"holds {FailingWriter.room} of the {FailingWriter.room + 3} frames"):
        video.close()


def test_a_runs_film_that_fails_stops_with_its_table_listing_the_frames_it_holds(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cv2, "VideoWriter", FailingWriter)
    film = FilmRecord(tmp_path, 240.0, WIDTH, HEIGHT)
    for index in range(FailingWriter.room + 2):
        frame = CameraFrame(index=index, t_start=index / 240.0, exposure_s=1 / 240.0, image=numbered(index))
        try:
            film.write(frame)
        except RigError:
            break
    with pytest.raises(RigError, match="could not be written"):
        film.close()
    with open(tmp_path / FRAMES_FILE, newline="") as file:
        rows = list(csv.DictReader(file))
    numbers, _, stated_count = avi_numbers(film.video_path)
    assert [int(row["frame"]) for row in rows] == numbers == list(range(FailingWriter.room))
    assert stated_count == film.frames == FailingWriter.room


class FullDiskContainer:
    """A PyAV output container whose disk fills after `room` packets: later muxing fails as an
    operating system's write does."""

    room = 8

    def __init__(self, container: av.container.OutputContainer) -> None:
        self._container = container
        self._muxed = 0

    def add_stream(self, *args: object, **kwargs: object) -> av.VideoStream:
        return self._container.add_stream(*args, **kwargs)

    def mux(self, packet: av.Packet) -> None:
        if self._muxed >= self.room:
            raise OSError(errno.ENOSPC, "No space left on device")
        self._container.mux(packet)
        self._muxed += 1

    def close(self) -> None:
        self._container.close()


def test_a_stamped_film_that_fails_raises_and_leaves_a_readable_film_saying_what_it_holds(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    opened = av.open
    monkeypatch.setattr(av, "open", lambda *args, **kwargs: FullDiskContainer(opened(*args, **kwargs)))
    video = StampedVideoRecord(tmp_path / "film.mp4", "mp4", "h264", 240.0, WIDTH, HEIGHT)
    with pytest.raises(RigError, match=f"holds {FullDiskContainer.room} of the") as failure:
        with video:
            for index in range(60):
                video.write(numbered(index), index / 240.0)
    assert "is the disk full?" in str(failure.value)
    assert video.muxed == FullDiskContainer.room
    monkeypatch.undo()
    with av.open(str(tmp_path / "film.mp4")) as film:
        assert film.streams.video[0].frames == FullDiskContainer.room


@pytest.mark.slow
def test_a_2000_fps_simulation_in_an_mp4_films_every_frame_and_analyses(tmp_path: Path) -> None:
    camera = CameraConfig(fps=2000.0, width=320, height=240, subsamples=2, container="mp4")
    config = SimulationConfig(duration_s=2.5, camera=camera, display=DisplayConfig(width=160, height=120))
    result = simulate(config, tmp_path)
    frames = result.truth.frames
    assert frames == 4999  # the sensor's exposures ending in the 2.5 s filmed
    with av.open(str(result.video_path)) as film:
        assert film.streams.video[0].frames == frames
    for table in (FRAMES_FILE, FRAME_TIMES_FILE):
        assert len((tmp_path / table).read_text().splitlines()) == frames + 1
    measured = analyse(result.video_path, AnalysisOptions())
    low, high = measured.ci95_ms
    assert low <= result.truth.latency_ms <= high
