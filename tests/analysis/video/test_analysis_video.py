"""Opening videos, image folders and frame arrays: frames, their stamps, and the errors a user can cause."""

import itertools
import threading

import cv2
import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions, analyse
from analysis.video.array import FrameArray
from analysis.video.decoding import DECODE_BATCH, READ_AHEAD, decode_threads, ordered_map
from analysis.video.file import VideoFile
from analysis.video.frames import Crop
from analysis.video.images import ImageFolder
from analysis.video.sources import open_frames


@pytest.fixture
def opencv_threads():
    """Sets OpenCV's thread count (which the decoder follows) for one test, then restores it."""
    before = cv2.getNumThreads()
    yield cv2.setNumThreads
    cv2.setNumThreads(before)


def moving_squares(count: int = 12, width: int = 48, height: int = 32) -> np.ndarray:
    frames = np.full((count, height, width), 20, dtype=np.uint8)
    for i in range(count):
        frames[i, 8:16, 2 + 3 * i : 10 + 3 * i] = 200
    return frames


def write_video(path, frames: np.ndarray, fourcc: str, fps: float = 240.0):
    writer = cv2.VideoWriter(
        str(path), cv2.VideoWriter_fourcc(*fourcc), fps, (frames.shape[2], frames.shape[1])
    )
    for frame in frames:
        writer.write(cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR))
    writer.release()
    return path


def test_mjpg_file_gives_grey_frames_and_its_frame_rate(tmp_path):
    frames = moving_squares()
    video = open_frames(write_video(tmp_path / "clip.avi", frames, "MJPG"))
    stamps, decoded = zip(*video.frames(), strict=True)
    decoded = np.stack(decoded)
    assert np.array(stamps) == pytest.approx(np.arange(12) / 240.0, abs=1e-6)
    assert video.fps == 240.0
    assert video.frame_size == (48, 32)
    assert video.frame_count == 12
    assert decoded.dtype == np.uint8 and decoded.shape == frames.shape
    assert np.abs(decoded.astype(int) - frames).mean() < 2.0


def test_lossless_file_read_the_ordinary_way_is_exact(tmp_path):
    frames = moving_squares()
    video = VideoFile(write_video(tmp_path / "clip.avi", frames, "FFV1", fps=90.0))
    assert video.fps == 90.0
    assert np.array_equal(np.stack([frame for _, frame in video.frames()]), frames)


def test_explicit_frame_rate_wins_over_the_container(tmp_path):
    video = open_frames(write_video(tmp_path / "clip.avi", moving_squares(), "MJPG"), fps=120.0)
    assert video.fps == 120.0


def test_missing_file_raises(tmp_path):
    with pytest.raises(AnalysisError, match="does not exist"):
        analyse(tmp_path / "nowhere.avi")


def test_file_that_is_not_a_video_raises(tmp_path):
    path = tmp_path / "notes.avi"
    path.write_text("these are my notes, not a video\n" * 20)
    with pytest.raises(AnalysisError, match="cannot be read as a video"):
        analyse(path)


def test_video_without_frames_raises(tmp_path):
    path = tmp_path / "empty.avi"
    cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 240.0, (48, 32)).release()
    with pytest.raises(AnalysisError, match="no frames"):
        analyse(path)


def test_empty_array_raises():
    with pytest.raises(AnalysisError, match="empty"):
        analyse(np.zeros((0, 32, 48), dtype=np.uint8), AnalysisOptions(fps=240.0))


@pytest.mark.parametrize("shape", [(32, 48), (4, 32, 48, 2)], ids=["one frame", "two channels"])
def test_array_of_the_wrong_shape_raises(shape):
    with pytest.raises(AnalysisError, match="shape"):
        open_frames(np.zeros(shape, dtype=np.uint8), fps=240.0)


def test_array_without_frame_rate_raises():
    with pytest.raises(AnalysisError, match="no frame rate is known"):
        analyse(moving_squares())


@pytest.mark.parametrize("fps", [0.0, -30.0, float("nan"), float("inf")])
def test_frame_rate_that_is_not_positive_raises(fps):
    with pytest.raises(AnalysisError, match="frame rate"):
        open_frames(moving_squares(), fps=fps)


def test_source_of_another_kind_raises():
    with pytest.raises(AnalysisError, match="video file, a folder of images or a numpy array"):
        open_frames([[1, 2], [3, 4]], fps=30.0)


def test_bgr_array_frames_are_made_grey():
    grey = moving_squares()
    frames = [frame for _, frame in FrameArray(np.repeat(grey[..., None], 3, axis=3), 30.0).frames()]
    assert np.array_equal(np.stack(frames), grey)


def test_float_array_frames_stay_float():
    grey = moving_squares().astype(np.float64) / 255
    stamps, frames = zip(*FrameArray(grey, 30.0).frames(), strict=True)
    assert stamps == pytest.approx(np.arange(grey.shape[0]) / 30.0)
    assert frames[0].dtype == np.float32
    assert np.allclose(np.stack(frames), grey, atol=1e-7)


@pytest.mark.parametrize(
    ("fourcc", "suffix"),
    [("mp4v", ".mp4"), ("XVID", ".avi"), ("MJPG", ".mkv"), ("mp4v", ".mov")],
    ids=["mpeg4-mp4", "xvid-avi", "mjpeg-mkv", "mpeg4-mov"],
)
def test_other_codecs_and_containers_give_frames_and_stamps(tmp_path, fourcc, suffix):
    frames = moving_squares(count=20)
    video = open_frames(write_video(tmp_path / f"clip{suffix}", frames, fourcc, fps=120.0))
    stamps, decoded = zip(*video.frames(), strict=True)
    assert len(decoded) == 20
    assert decoded[0].shape == (32, 48)
    # Matroska keeps milliseconds: stamps are within half a millisecond of i / fps.
    assert np.array(stamps) == pytest.approx(np.arange(20) / 120.0, abs=6e-4)
    assert np.abs(np.stack(decoded).astype(int) - frames).mean() < 6.0


def write_images(folder, frames: np.ndarray, numbers) -> None:
    folder.mkdir()
    for number, frame in zip(numbers, frames, strict=True):
        cv2.imwrite(str(folder / f"frame_{number:05d}.png"), frame)


def test_image_folder_frames_are_in_number_order_with_gaps_as_time(tmp_path):
    frames = moving_squares(count=6)
    numbers = [3, 4, 5, 7, 8, 12]
    write_images(tmp_path / "shots", frames[::-1], numbers[::-1])
    video = open_frames(tmp_path / "shots", fps=100.0)
    assert isinstance(video, ImageFolder)
    stamps, decoded = zip(*video.frames(), strict=True)
    assert np.array(stamps) == pytest.approx((np.array(numbers) - 3) / 100.0)
    assert np.array_equal(np.stack(decoded), frames)
    assert (video.frame_count, video.frame_size) == (6, (48, 32))


def test_image_folder_needs_a_frame_rate(tmp_path):
    write_images(tmp_path / "shots", moving_squares(count=3), [1, 2, 3])
    with pytest.raises(AnalysisError, match="no frame rate is known"):
        analyse(tmp_path / "shots")


def test_image_folder_without_numbers_or_images_raises(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(AnalysisError, match="holds no images"):
        open_frames(tmp_path / "empty", fps=30.0)
    (tmp_path / "named").mkdir()
    cv2.imwrite(str(tmp_path / "named" / "first.png"), moving_squares(count=1)[0])
    with pytest.raises(AnalysisError, match="without a frame number"):
        open_frames(tmp_path / "named", fps=30.0)


def test_image_folder_with_a_frame_of_another_size_raises(tmp_path):
    write_images(tmp_path / "shots", moving_squares(count=3), [1, 2, 3])
    cv2.imwrite(str(tmp_path / "shots" / "frame_00004.png"), np.zeros((10, 10), dtype=np.uint8))
    with pytest.raises(AnalysisError, match="10x10"):
        list(open_frames(tmp_path / "shots", fps=30.0).frames())


def test_corrupt_image_in_a_later_batch_is_named(tmp_path):
    write_images(tmp_path / "shots", moving_squares(count=20), range(1, 21))
    (tmp_path / "shots" / "frame_00013.png").write_bytes(b"not a png" * 50)
    frames = open_frames(tmp_path / "shots", fps=30.0).frames()
    with pytest.raises(AnalysisError, match="frame_00013.png is corrupt"):
        list(frames)


def test_items_come_in_order_when_the_consumer_maps_some_itself(opencv_threads):
    # Each side's first item waits until the other side has mapped one: the consumer must then map
    # a batch that no worker had started, while a worker maps another.
    opencv_threads(2)
    mapped_by = {}
    worker_started, consumer_started = threading.Event(), threading.Event()

    def square(item: int) -> np.ndarray:
        consumer = threading.current_thread() is threading.main_thread()
        mine, other = (consumer_started, worker_started) if consumer else (worker_started, consumer_started)
        mine.set()
        assert other.wait(timeout=30), "the other side never mapped an item"
        mapped_by[item] = consumer
        return np.array([item * item])

    count = 3 * READ_AHEAD + 5
    results = list(ordered_map(square, range(count), str))
    assert [int(r[0]) for r in results] == [i * i for i in range(count)]
    assert set(mapped_by.values()) == {True, False}


def test_with_one_thread_the_consumer_maps_every_item_in_order(opencv_threads):
    opencv_threads(1)
    assert decode_threads() == 1
    mapped_by = set()

    def square(item: int) -> np.ndarray:
        mapped_by.add(threading.current_thread())
        return np.array([item * item])

    count = 3 * READ_AHEAD + 5
    results = list(ordered_map(square, range(count), str))
    assert [int(r[0]) for r in results] == [i * i for i in range(count)]
    assert mapped_by == {threading.main_thread()}


@pytest.mark.parametrize("threads", [1, 2])
def test_a_frame_that_cannot_be_decoded_is_named_on_any_number_of_threads(opencv_threads, threads):
    opencv_threads(threads)
    results = ordered_map(lambda item: None if item == 13 else np.array([item]), range(40), lambda i: f"frame {i}")
    with pytest.raises(AnalysisError, match="frame 13 is corrupt"):
        list(results)


def test_closing_the_frames_early_stops_the_decoding():
    mapped = []

    def record(item: int) -> np.ndarray:
        mapped.append(item)
        return np.array([item])

    results = ordered_map(record, range(100 * READ_AHEAD), str)
    assert int(next(results)[0]) == 0
    results.close()
    assert len(mapped) <= READ_AHEAD + DECODE_BATCH


@pytest.mark.parametrize("fourcc", ["MJPG", "FFV1"], ids=["decoded in rectangles", "read whole and cut"])
def test_frames_after_the_crop_is_set_are_its_rectangle(tmp_path, fourcc):
    count = READ_AHEAD + 3 * DECODE_BATCH + 5
    frames = moving_squares(count=count, width=320, height=64)
    video = VideoFile(write_video(tmp_path / "clip.avi", frames, fourcc))
    whole = [frame for _, frame in video.frames()]
    crop = Crop()
    stream = video.frames(crop)
    before = [frame for _, frame in itertools.islice(stream, 5)]
    crop.to(slice(6, 20), slice(3, 300))
    after = [frame for _, frame in stream]
    assert [frame.shape for frame in before] == [(64, 320)] * 5
    assert [frame.shape for frame in after] == [(14, 297)] * (count - 5)
    assert all(np.array_equal(frame, w[6:20, 3:300]) for frame, w in zip(after, whole[5:], strict=True))
    # Frames read ahead before the crop was set are cut from whole frames (views); later MJPEG
    # frames are decoded as rectangles (their own pixels).
    assert not after[0].flags.owndata
    assert after[-1].flags.owndata == (fourcc == "MJPG")


def test_an_array_of_frames_is_cut_once_the_crop_is_set():
    frames = moving_squares(count=6)
    crop = Crop()
    stream = FrameArray(frames, 30.0).frames(crop)
    assert next(stream)[1].shape == (32, 48)
    crop.to(slice(4, 20), slice(10, 30))
    assert all(np.array_equal(frame, whole[4:20, 10:30]) for (_, frame), whole in zip(stream, frames[1:], strict=True))


def test_a_file_calibrated_on_a_sample_of_its_frames_is_tracked_as_its_whole_frames_are(
    tmp_path, scene, render_video, mjpg_file
):
    # At 240 fps a Motion-JPEG file is calibrated on every third of its first frames, then read
    # again in rectangles; the same frames held in memory are calibrated on all of them, whole.
    # The backgrounds then come from other frames, whose noise moves a centroid by hundredths of
    # a pixel (measured: 0.07 px at most, 0.006 ms of latency).
    clip = scene(duration_s=3.2, period_s=0.8)
    path = mjpg_file(tmp_path / "clip.avi", render_video(clip), clip.fps)
    assert VideoFile(path).decodes_in_part
    decoded = np.stack([frame for _, frame in VideoFile(path).frames()])
    from_file, from_array = analyse(path), analyse(decoded, AnalysisOptions(fps=clip.fps))
    assert from_file.frames == from_array.frames == len(decoded)
    for name in ("led_track", "sphere_track"):
        file_track, array_track = getattr(from_file, name), getattr(from_array, name)
        assert np.array_equal(file_track.valid, array_track.valid)
        assert np.nanmax(np.abs(file_track.x - array_track.x)) < 0.15
        assert np.nanmax(np.abs(file_track.y - array_track.y)) < 0.15
    assert from_file.latency_ms == pytest.approx(from_array.latency_ms, abs=0.02)


@pytest.mark.parametrize("source", ["MJPG", "FFV1", "array", "images"])
def test_every_nth_frame_comes_with_its_own_stamp(tmp_path, source):
    frames = moving_squares(count=14)
    if source == "array":
        video = FrameArray(frames, 30.0)
    elif source == "images":
        write_images(tmp_path / "shots", frames, range(1, 15))
        video = ImageFolder(tmp_path / "shots", 30.0)
    else:
        video = VideoFile(write_video(tmp_path / "clip.avi", frames, source, fps=30.0))
    stamps, whole = zip(*video.frames(), strict=True)
    every_third = list(video.frames(every=3))
    assert [stamp for stamp, _ in every_third] == list(stamps[::3])
    assert all(np.array_equal(frame, w) for (_, frame), w in zip(every_third, whole[::3], strict=True))
