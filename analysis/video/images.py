"""A folder of numbered images, one per frame."""

from __future__ import annotations

import re
from collections.abc import Generator, Iterator
from pathlib import Path

import cv2

from analysis.errors import AnalysisError
from analysis.video.decoding import ordered_map
from analysis.video.frames import Crop, Frame, Repeats, checked_every, checked_fps, cut_frames, noted_repeats
from analysis.video.native_path import native_path

IMAGE_SUFFIXES = frozenset({".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".webp"})


def _frame_number(path: Path) -> int | None:
    numbers = re.findall(r"\d+", path.stem)
    return int(numbers[-1]) if numbers else None


class ImageFolder:
    """A folder of numbered images (frame_0001.png, ...): frame n was taken at n / fps.

    The number is the last run of digits in each file name; gaps in the numbering are dropped
    frames and show as gaps in time.
    """

    def __init__(self, folder: Path, fps: float | None) -> None:
        images = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())
        if not images:
            raise AnalysisError(
                f"{folder} holds no images ({', '.join(sorted(IMAGE_SUFFIXES))}); give a video file or a folder of frames"
            )
        unnumbered = [p.name for p in images if _frame_number(p) is None]
        if unnumbered:
            raise AnalysisError(
                f"{folder} holds images without a frame number, e.g. {unnumbered[0]}; name them like frame_0001.png"
            )
        numbered = sorted((_frame_number(p), p) for p in images)
        repeated = [n for (n, _), (m, _) in zip(numbered, numbered[1:]) if n == m]
        if repeated:
            raise AnalysisError(f"{folder} holds two images numbered {repeated[0]}; keep one image per frame number")
        self._numbers = [n for n, _ in numbered]
        self._paths = [native_path(p) for _, p in numbered]
        checked = checked_fps(fps)
        if checked is None:
            raise AnalysisError(
                f"no frame rate is known for the images in {folder}; pass --fps (fps=) with the camera's frame rate"
            )
        self._fps = checked
        first = cv2.imread(self._paths[0], cv2.IMREAD_GRAYSCALE)
        if first is None:
            raise AnalysisError(f"{self._paths[0]} cannot be read as an image")
        self._frame_size = int(first.shape[1]), int(first.shape[0])
        self._folder = folder

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def container_fps(self) -> None:
        return None

    @property
    def frame_size(self) -> tuple[int, int]:
        return self._frame_size

    @property
    def frame_count(self) -> int:
        return len(self._paths)

    @property
    def name(self) -> str:
        return str(self._folder)

    @property
    def stamp_origin(self) -> str:
        return "image number"

    @property
    def decodes_in_part(self) -> bool:
        return False

    def frames(self, crop: Crop | None = None, every: int = 1, repeats: Repeats | None = None) -> Iterator[Frame]:
        every = checked_every(every)
        return cut_frames(noted_repeats(self._grey_frames(every), repeats, every), crop)

    def _grey_frames(self, every: int) -> Generator[Frame, None, None]:
        paths = self._paths[::every]
        decoded = ordered_map(
            lambda path: cv2.imread(path, cv2.IMREAD_GRAYSCALE),
            paths,
            lambda index: f"image {paths[index]}",
        )
        for number, frame in zip(self._numbers[::every], decoded, strict=False):
            if (frame.shape[1], frame.shape[0]) != self._frame_size:
                raise AnalysisError(
                    f"image number {number} in {self._folder} is {frame.shape[1]}x{frame.shape[0]}, not "
                    f"{self._frame_size[0]}x{self._frame_size[1]} like the first; keep one camera's frames per folder"
                )
            yield (number - self._numbers[0]) / self._fps, frame
