"""Regions of interest and blob tracking: where the LED and the sphere are in every frame.

Pixel coordinates are (x right, y down) with the centre of the top-left pixel at (0, 0). A blob's
position is the intensity-weighted centroid of the pixels in its ROI that stand out from the ROI's
background by more than a threshold. The weights are the background-subtracted intensities
themselves (not intensity minus threshold), so the centroid stays linear in the image: a blob
smeared by motion blur, or the double image of a display refresh during the exposure, gives the
exposure-averaged position, which keeps the timing of the signal unbiased.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from analysis.errors import AnalysisError

# A pixel belongs to a blob if it exceeds the background by this many noise standard deviations...
NOISE_SIGMAS = 6.0
# ...and by this fraction of the blob's typical peak (guards noise-free or heavily compressed video).
PEAK_FRACTION_THRESHOLD = 0.05
# A frame has a blob if its peak exceeds this fraction of the typical peak (and twice the threshold).
PEAK_FRACTION_VALID = 0.25
# Frames used to estimate each ROI's background and noise.
CALIBRATION_SAMPLES = 64
# Dilation radius joining the dotted trail of a sphere held still between display refreshes,
# as a fraction of the larger frame side.
TRAIL_JOIN_FRACTION = 0.02
# Moving-region threshold: this fraction of the way from the typical to the largest temporal
# intensity range, and at least this many pixel-noise deviations above the typical range.
MOTION_FRACTION = 0.1
MOTION_NOISE_SIGMAS = 10.0
PROGRESS_EVERY = 64

MAD_TO_SIGMA = 1.4826


@dataclass(frozen=True)
class Roi:
    """A pixel rectangle [x, y, width, height] inside a frame."""

    x: int
    y: int
    width: int
    height: int

    @classmethod
    def parse(cls, values: Sequence[float], frame_size: tuple[int, int], name: str) -> Roi:
        """An ROI from [x, y, w, h]; raises AnalysisError unless it has positive size inside the frame."""
        width_px, height_px = frame_size
        hint = f"give the {name} ROI as [x, y, width, height] inside the {width_px}x{height_px} frame"
        try:
            numbers = [float(v) for v in values]
        except (TypeError, ValueError):
            raise AnalysisError(f"{name} ROI {values!r} is not four numbers; {hint}") from None
        if len(numbers) != 4 or not all(n.is_integer() for n in numbers):
            raise AnalysisError(f"{name} ROI {list(values)!r} is not four whole numbers; {hint}")
        x, y, w, h = (int(n) for n in numbers)
        if w <= 0 or h <= 0:
            raise AnalysisError(f"{name} ROI {[x, y, w, h]} has no area; {hint}")
        if x < 0 or y < 0 or x + w > width_px or y + h > height_px:
            raise AnalysisError(f"{name} ROI {[x, y, w, h]} reaches outside the frame; {hint}")
        return cls(x, y, w, h)

    def as_list(self) -> list[int]:
        return [self.x, self.y, self.width, self.height]

    def crop(self, frame: np.ndarray) -> np.ndarray:
        """A view of the ROI's pixels in a frame."""
        return frame[self.y : self.y + self.height, self.x : self.x + self.width]


@dataclass(frozen=True)
class Track:
    """A blob's position per frame. x and y are NaN where valid is False (no blob in that frame).

    peak is the blob's brightest pixel above the ROI background, per frame.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    valid: np.ndarray
    peak: np.ndarray


@dataclass(frozen=True)
class BlobModel:
    """What the tracker knows of one ROI: its static background and how bright a blob is."""

    roi: Roi
    background: np.ndarray
    threshold: float
    min_peak: float
    typical_peak: float


def find_moving_regions(frames: Sequence[np.ndarray]) -> list[Roi]:
    """ROIs around the bright regions whose intensity changes over the frames, largest first.

    Moving pixels are those whose range (temporal max minus min) stands well above the typical
    range, which is what noise gives static pixels; the pixel noise itself is estimated from the
    difference of two frames. Dilation joins the dotted trail that a sphere held between display
    refreshes leaves, and each ROI is padded by the dilation radius again so that the blob stays
    inside it. An empty list means nothing moves.
    """
    height, width = frames[0].shape
    high = frames[0].copy()
    low = frames[0].copy()
    for frame in frames[1:]:
        cv2.max(high, frame, dst=high)
        cv2.min(low, frame, dst=low)
    spread = cv2.subtract(high, low).astype(np.float64)
    typical = float(np.median(spread))
    largest = float(spread.max())
    change = frames[len(frames) // 2].astype(np.float64) - frames[0]
    noise = MAD_TO_SIGMA * float(np.median(np.abs(change - np.median(change)))) / np.sqrt(2)
    if largest - typical <= MOTION_NOISE_SIGMAS * noise:
        return []
    margin = max(MOTION_FRACTION * (largest - typical), MOTION_NOISE_SIGMAS * noise)
    mask = (spread > typical + margin).astype(np.uint8)
    radius = max(2, round(TRAIL_JOIN_FRACTION * max(width, height)))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    count, _, stats, _ = cv2.connectedComponentsWithStats(cv2.dilate(mask, kernel), connectivity=8)
    order = np.argsort(-stats[1:, cv2.CC_STAT_AREA], kind="stable") + 1
    regions = []
    for label in order[: count - 1]:
        x, y, w, h = (int(v) for v in stats[label, :4])
        x0, y0 = max(x - radius, 0), max(y - radius, 0)
        x1, y1 = min(x + w + radius, width), min(y + h + radius, height)
        regions.append(Roi(x0, y0, x1 - x0, y1 - y0))
    return regions


def calibrate_blob(roi: Roi, frames: Sequence[np.ndarray], name: str) -> BlobModel:
    """Background (per-pixel temporal median), noise and blob brightness of an ROI.

    Uses up to CALIBRATION_SAMPLES frames spread over ``frames``; the median is the background as
    long as the blob covers each pixel in fewer than half of them, which holds for a swinging
    pendulum seen over at least half a period.
    """
    step = max(1, len(frames) // CALIBRATION_SAMPLES)
    crops = np.stack([roi.crop(frame) for frame in frames[::step][:CALIBRATION_SAMPLES]])
    median = np.median(crops, axis=0)
    background = (np.rint(median) if crops.dtype == np.uint8 else median).astype(crops.dtype)
    diff = crops.astype(np.float64) - background
    noise = MAD_TO_SIGMA * float(np.median(np.abs(diff)))
    typical_peak = float(np.median(diff.max(axis=(1, 2))))
    if typical_peak <= 2 * NOISE_SIGMAS * noise or typical_peak <= 0:
        raise AnalysisError(
            f"no moving blob stands out in the {name} ROI {roi.as_list()}; check that the pendulum "
            "swings and that the ROI holds the blob over its whole swing"
        )
    threshold = max(NOISE_SIGMAS * noise, PEAK_FRACTION_THRESHOLD * typical_peak)
    min_peak = max(2 * threshold, PEAK_FRACTION_VALID * typical_peak)
    return BlobModel(roi, np.ascontiguousarray(background), threshold, min_peak, typical_peak)


def locate_blob(model: BlobModel, frame: np.ndarray) -> tuple[float, float, float, bool]:
    """(x, y, peak, valid) of the blob in one frame; x and y are NaN when no blob is bright enough."""
    diff = cv2.subtract(model.roi.crop(frame), model.background)
    peak = cv2.minMaxLoc(diff)[1]
    if peak < model.min_peak:
        return np.nan, np.nan, peak, False
    # Moments over the bounding box of the kept pixels: the same sums, at a fraction of the cost.
    x, y, w, h = cv2.boundingRect(cv2.compare(diff, model.threshold, cv2.CMP_GT))
    weights = cv2.threshold(diff[y : y + h, x : x + w], model.threshold, 0, cv2.THRESH_TOZERO)[1]
    moments = cv2.moments(weights)
    mass = moments["m00"]
    return model.roi.x + x + moments["m10"] / mass, model.roi.y + y + moments["m01"] / mass, peak, True


def track_blobs(
    frames: Iterable[np.ndarray],
    models: Sequence[BlobModel],
    fps: float,
    total: int,
    progress: Callable[[int, int], object] | None = None,
) -> list[Track]:
    """One track per model over all frames; ``progress(done, total)`` is called as frames go by."""
    rows: list[list[tuple[float, float, float, bool]]] = [[] for _ in models]
    done = 0
    for frame in frames:
        for model, row in zip(models, rows, strict=True):
            row.append(locate_blob(model, frame))
        done += 1
        if progress is not None and done % PROGRESS_EVERY == 0:
            progress(done, max(total, done))
    if progress is not None:
        progress(done, done)
    times = np.arange(done, dtype=np.float64) / fps
    tracks = []
    for row in rows:
        x, y, peak, valid = zip(*row, strict=True)
        tracks.append(
            Track(
                times,
                np.array(x, dtype=np.float64),
                np.array(y, dtype=np.float64),
                np.array(valid, dtype=bool),
                np.array(peak, dtype=np.float64),
            )
        )
    return tracks
