"""Regions of interest and blob tracking: where the LED and the sphere are in every frame.

Pixel coordinates are (x right, y down) with the centre of the top-left pixel at (0, 0). A blob's
core is the set of pixels that stand out from the ROI's static background by more than a
threshold; its position is the centroid of the background-subtracted intensities over the box
around the core grown by a margin, signed and not thresholded, so the centroid stays linear in
the image: a blob smeared by motion blur, or the double image of a display refresh during the
exposure, gives the exposure-averaged position, which keeps the timing of the signal unbiased (a
threshold would cut the fainter image's edges more than the brighter's and bias the time).
Saturated cores and bloom are symmetric about the blob and do not move its centroid.

The background is each ROI's per-pixel temporal median, so static bright clutter (a reflection, a
lamp) is subtracted away: only what moves counts. Each blob is measured in a small window that
follows it (its last position plus its last step); the window grows until no pixel of the blob
touches its edge, so it never cuts the blob. When the blob is not in its window it is searched
for in the whole ROI, around the ROI's brightest pixel. A blob that touches the edge of its ROI is
cut off: that frame's position is not valid (``clipped``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import cv2
import numpy as np

from analysis.errors import AnalysisError

# A pixel belongs to a blob if it exceeds the background by this many noise standard deviations...
NOISE_SIGMAS = 6.0
# ...and by this fraction of the blob's typical peak (guards noise-free or heavily compressed video).
PEAK_FRACTION_THRESHOLD = 0.05
# A frame has a blob if its peak exceeds this fraction of the typical peak (and twice the threshold).
PEAK_FRACTION_VALID = 0.25
# Frames used to estimate each ROI's background and noise (odd: the median is one of them).
CALIBRATION_SAMPLES = 9
# find_moving_regions looks at about this many frames spread over those it is given.
REGION_FRAMES = 120
# Every this many pixels enter the image-wide statistics of find_moving_regions.
STATISTICS_STRIDE = 7
# Dilation radius joining the dotted trail of a sphere held still between display refreshes,
# as a fraction of the larger frame side.
TRAIL_JOIN_FRACTION = 0.02
# Pixels added to an ROI beyond twice that radius (see find_moving_regions).
ROI_PAD_PX = 4
# Moving pixels: a temporal intensity range this many pixel-noise deviations above the typical
# range, and at least this fraction of the way from the typical to the largest range.
MOTION_NOISE_SIGMAS = 10.0
MOTION_FRACTION = 0.03
# A moving region needs this many moving pixels, and this fraction of the largest region's
# (isolated noise outliers and compression speckle are not regions).
MIN_MOVING_PIXELS = 10
MIN_MOVING_FRACTION = 0.05
# Pixels added around a blob's calibrated reach and its last step to make its search window.
WINDOW_MARGIN_PX = 4
# The centroid sums the background-subtracted pixels, signed and unthresholded, over the box around
# the blob's above-threshold core grown by this fraction of its reach (at least 2 px; when stray
# pieces were cut away, over the core's pixels grown as much): the faint edges of a blob and the
# fainter image of a double exposure count in full, as linearity needs.
SUPPORT_GROWTH = 0.5
# Times a window may double before the whole ROI is used.
WINDOW_GROWTH = 3

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

    t is the frame time in s; peak is the blob's brightest pixel above the ROI background;
    clipped marks frames where the blob touched its ROI's edge (so it is not valid there). Where
    the tracker measured them (NaN in frames without a blob): level is the brightest pixel's own
    value (saturation shows there), mass the blob's summed intensity above the background, and
    spread (N, 3) its intensity-weighted second central moments xx, yy, xy in px^2 (its size,
    and its motion blur along the way it moves).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    valid: np.ndarray
    peak: np.ndarray
    clipped: np.ndarray
    level: np.ndarray | None = None
    mass: np.ndarray | None = None
    spread: np.ndarray | None = None


@dataclass(frozen=True)
class BlobModel:
    """What the tracker knows of one ROI: its static background, how bright a blob is and how far
    its pixels reach from its centroid (motion blur included)."""

    roi: Roi
    background: np.ndarray
    threshold: float
    min_peak: float
    typical_peak: float
    reach: float


class Detection(NamedTuple):
    """One blob in one frame; x, y in frame pixels, NaN when not valid; level, mass and the second
    moments as in ``Track``, NaN where the blob was not measured."""

    x: float
    y: float
    peak: float
    valid: bool
    clipped: bool
    level: float = math.nan
    mass: float = math.nan
    sxx: float = math.nan
    syy: float = math.nan
    sxy: float = math.nan


def find_moving_regions(frames: Sequence[np.ndarray]) -> list[Roi]:
    """ROIs around the bright regions whose intensity changes over the frames, most moving pixels first.

    Moving pixels are those whose range (temporal max minus min) stands well above the typical
    range, which is what noise gives static pixels; the pixel noise itself is estimated from the
    difference of two frames. The threshold follows the noise, so a dim sphere next to a bright
    LED is found too. Dilation joins the dotted trail that a sphere held between display refreshes
    leaves, and each ROI is padded by twice the dilation radius and ROI_PAD_PX more, so that the
    blob's faint edges, which the tracker counts but the motion threshold does not, stay inside;
    towards a neighbouring region it grows by at most half the gap, so no ROI reaches into another.
    An empty list means nothing moves.
    """
    height, width = frames[0].shape
    high = frames[0].copy()
    low = frames[0].copy()
    for frame in frames[1 :: max(1, len(frames) // REGION_FRAMES)]:
        cv2.max(high, frame, dst=high)
        cv2.min(low, frame, dst=low)
    spread = cv2.subtract(high, low)
    typical = float(np.median(spread.reshape(-1)[::STATISTICS_STRIDE]))
    largest = float(spread.max())
    change = (frames[len(frames) // 2].astype(np.float64) - frames[0]).reshape(-1)[::STATISTICS_STRIDE]
    noise = MAD_TO_SIGMA * float(np.median(np.abs(change - np.median(change)))) / np.sqrt(2)
    if largest - typical <= MOTION_NOISE_SIGMAS * noise:
        return []
    margin = max(MOTION_FRACTION * (largest - typical), MOTION_NOISE_SIGMAS * noise)
    mask = (spread > typical + margin).astype(np.uint8)
    radius = max(2, round(TRAIL_JOIN_FRACTION * max(width, height)))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    pad = 2 * radius + ROI_PAD_PX
    count, labels, stats, _ = cv2.connectedComponentsWithStats(cv2.dilate(mask, kernel), connectivity=8)
    moving = np.bincount(labels[mask > 0], minlength=count)
    order = np.argsort(-moving[1:], kind="stable") + 1
    least = max(MIN_MOVING_PIXELS, MIN_MOVING_FRACTION * moving[order[0]]) if count > 1 else 0
    kept = [label for label in order if moving[label] >= least]
    boxes = [tuple(int(v) for v in stats[label, :4]) for label in kept]
    return [_padded(box, [b for b in boxes if b is not box], pad, width, height) for box in boxes]


def _padded(
    box: tuple[int, int, int, int], others: list[tuple[int, int, int, int]], pad: int, width: int, height: int
) -> Roi:
    """A box grown by ``pad`` on each side, but on a side facing another box by at most half the gap."""
    x, y, w, h = box
    left = right = top = bottom = pad
    for ox, oy, ow, oh in others:
        if oy < y + h and y < oy + oh:
            if ox >= x + w:
                right = min(right, (ox - x - w) // 2)
            elif ox + ow <= x:
                left = min(left, (x - ox - ow) // 2)
        if ox < x + w and x < ox + ow:
            if oy >= y + h:
                bottom = min(bottom, (oy - y - h) // 2)
            elif oy + oh <= y:
                top = min(top, (y - oy - oh) // 2)
    x0, y0 = max(x - left, 0), max(y - top, 0)
    x1, y1 = min(x + w + right, width), min(y + h + bottom, height)
    return Roi(x0, y0, x1 - x0, y1 - y0)


def _blob_reach(diffs: np.ndarray, threshold: float, min_peak: float) -> float:
    """How far (px) a blob reaches from its centre: half the larger side of the box around the
    above-threshold piece that holds the brightest pixel, 90th percentile over frames with a blob."""
    reaches = []
    for diff in diffs:
        _, peak, _, top = cv2.minMaxLoc(diff)
        if peak < min_peak:
            continue
        _, _, _, (_, _, w, h) = cv2.floodFill((diff > threshold).view(np.uint8), None, top, 2, flags=8)
        reaches.append(max(w, h) / 2 + 1)
    return float(np.percentile(reaches, 90)) if reaches else float(max(diffs.shape[1:]))


def _noise_sigma(diff: np.ndarray, integer: bool) -> float:
    """Standard deviation of the pixel noise about the background (MAD estimate), at least one
    level for 8-bit images: a compressed dark background is flat, its MAD zero, yet it flickers
    by a few levels."""
    sample = np.abs(diff.reshape(-1)[::STATISTICS_STRIDE])
    robust = MAD_TO_SIGMA * float(np.median(sample))
    return max(robust, 1.0) if integer else robust


def calibrate_blob(roi: Roi, frames: Sequence[np.ndarray], name: str) -> BlobModel:
    """Background (per-pixel temporal median), noise, blob brightness and reach of an ROI.

    Uses up to CALIBRATION_SAMPLES frames spread over ``frames`` (the lower middle value for an
    even number); the median is the background as long as the blob covers each pixel in fewer than
    half of them, which holds for a swinging pendulum seen over at least half a period.
    """
    step = max(1, len(frames) // CALIBRATION_SAMPLES)
    crops = np.stack([roi.crop(frame) for frame in frames[::step][:CALIBRATION_SAMPLES]])
    middle = (len(crops) - 1) // 2
    background = np.ascontiguousarray(np.partition(crops, middle, axis=0)[middle])
    diff = crops.astype(np.float32) - background
    noise = _noise_sigma(diff, crops.dtype == np.uint8)
    typical_peak = float(np.median(diff.max(axis=(1, 2))))
    if typical_peak <= 2 * NOISE_SIGMAS * noise or typical_peak <= 0:
        raise AnalysisError(
            f"no moving blob stands out in the {name} ROI {roi.as_list()}; check that the pendulum "
            "swings and that the ROI holds the blob over its whole swing"
        )
    threshold = max(NOISE_SIGMAS * noise, PEAK_FRACTION_THRESHOLD * typical_peak)
    min_peak = max(2 * threshold, PEAK_FRACTION_VALID * typical_peak)
    reach = _blob_reach(diff, threshold, min_peak)
    return BlobModel(roi, background, threshold, min_peak, typical_peak, reach)


class BlobTracker:
    """Follows one blob from frame to frame in a window around where it is expected.

    It runs for every frame on the thread that reads the video, alongside the decoding, so its
    per-frame work is a handful of small array operations on the window: the model's numbers are
    held as plain attributes, and differences are taken against a signed copy of the background
    (int16 for 8-bit frames: exact, and the core test becomes an integer comparison; float32
    otherwise, as OpenCV would compute them).
    """

    def __init__(self, model: BlobModel, origin: tuple[int, int] = (0, 0)) -> None:
        """``origin`` is the (x, y) in the frame of the first pixel of the images ``locate`` will
        get: (0, 0) for whole frames, the corner of the rectangle for cropped ones."""
        self.model = model
        roi = model.roi
        self._rows = slice(roi.y - origin[1], roi.y - origin[1] + roi.height)
        self._cols = slice(roi.x - origin[0], roi.x - origin[0] + roi.width)
        self._corner = (float(roi.x), float(roi.y))
        integer = model.background.dtype == np.uint8
        self._background = model.background.astype(np.int16 if integer else np.float32)
        # An integer difference exceeds the threshold exactly when it exceeds its floor.
        self._core_level = math.floor(model.threshold) if integer else float(model.threshold)
        self._strong_level = 2 * model.threshold
        self._min_peak = model.min_peak
        self._reach = model.reach
        self._spread = 2 * model.reach + 2
        self._grow = max(2, round(SUPPORT_GROWTH * model.reach))
        self._kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * self._grow + 1, 2 * self._grow + 1))
        self._position: tuple[float, float] | None = None
        self._step = (0.0, 0.0)
        # The window around the expected place reaches as far as the blob has ever moved in one
        # frame: a display holding each pose for several refreshes shows a still sphere that then
        # jumps, and a frame exposed across the jump holds both images, both of which count.
        self._longest_step = 0.0

    def locate(self, frame: np.ndarray) -> Detection:
        """The blob in one frame, or in its rectangle from the tracker's origin (frame pixel coordinates)."""
        crop = frame[self._rows, self._cols]
        position = self._position
        found = None
        if position is not None:
            step_x, step_y = self._step
            centre = (position[0] + step_x, position[1] + step_y)
            found = self._measure(crop, centre, self._reach + self._longest_step + WINDOW_MARGIN_PX)
        if found is None:
            _, peak, _, (px, py) = cv2.minMaxLoc(cv2.subtract(crop, self.model.background))
            if peak < self._min_peak:
                self._position = None
                return Detection(np.nan, np.nan, peak, False, False)
            found = self._measure(crop, (float(px), float(py)), self._reach + WINDOW_MARGIN_PX)
            if found is None:
                self._position = None
                return Detection(np.nan, np.nan, peak, False, False)
        x, y, peak, clipped, level, moments = found
        if clipped:
            self._position = None
            return Detection(np.nan, np.nan, peak, False, True)
        self._step = (x - position[0], y - position[1]) if position is not None else (0.0, 0.0)
        self._longest_step = max(self._longest_step, abs(self._step[0]), abs(self._step[1]))
        self._position = (x, y)
        mass = moments["m00"]
        return Detection(
            self._corner[0] + x, self._corner[1] + y, peak, True, False, level, mass,
            moments["mu20"] / mass, moments["mu02"] / mass, moments["mu11"] / mass,
        )  # fmt: skip

    def _measure(
        self, crop: np.ndarray, centre: tuple[float, float], half: float
    ) -> tuple[float, float, float, bool, float, dict[str, float]] | None:
        """(x, y, peak, clipped, level, moments) in ROI coordinates of the blob near ``centre``, or
        None if none there; level is the brightest pixel's value, moments OpenCV's of the blob."""
        background = self._background
        height, width = crop.shape
        grow = self._grow
        cx, cy = centre
        for _ in range(WINDOW_GROWTH + 1):
            x0, y0 = max(0, int(cx - half)), max(0, int(cy - half))
            x1, y1 = min(width, int(cx + half) + 2), min(height, int(cy + half) + 2)
            if x1 <= x0 or y1 <= y0:
                return None
            diff = crop[y0:y1, x0:x1] - background[y0:y1, x0:x1]
            _, peak, _, top = cv2.minMaxLoc(diff)
            if peak < self._min_peak:
                return None
            mask, (bx, by, bw, bh) = self._blob_mask(diff, top)
            sx0, sy0, sx1, sy1 = bx - grow, by - grow, bx + bw + grow, by + bh + grow
            cut = (sx0 < 0 < x0) or (sy0 < 0 < y0) or (sx1 > x1 - x0 and x1 < width) or (sy1 > y1 - y0 and y1 < height)
            if not cut:
                clipped = bx == 0 or by == 0 or bx + bw == x1 - x0 or by + bh == y1 - y0
                sx0, sy0, sx1, sy1 = max(sx0, 0), max(sy0, 0), min(sx1, x1 - x0), min(sy1, y1 - y0)
                weights = diff[sy0:sy1, sx0:sx1]
                if mask is not None:
                    weights = np.where(cv2.dilate(mask[sy0:sy1, sx0:sx1], self._kernel) > 0, weights, 0)
                moments = cv2.moments(weights)
                mass = moments["m00"]
                if mass <= 0:
                    # signed weights: a blob barely above the threshold can sum to nothing with its noise
                    return None
                level = float(crop[y0 + top[1], x0 + top[0]])
                return x0 + sx0 + moments["m10"] / mass, y0 + sy0 + moments["m01"] / mass, peak, clipped, level, moments
            cx, cy = x0 + bx + bw / 2, y0 + by + bh / 2
            half *= 2
        return self._measure(crop, (width / 2, height / 2), max(width, height))

    def _blob_mask(
        self, diff: np.ndarray, top: tuple[int, int]
    ) -> tuple[np.ndarray | None, tuple[int, int, int, int]]:
        """(mask, bounding box) of the blob's core in a window whose brightest pixel is ``top``: the
        pixels above the threshold in connected (8-neighbour) pieces that reach twice the threshold
        somewhere (so a stray noise pixel is not part of the blob, while the fainter image of a
        double exposure is). Pieces are only looked for when the pixels spread wider than the
        blob's calibrated reach or touch the window's edge; the mask is None when the whole box
        around the core is the blob's. The pieces are flood-filled: the brightest pixel's first, then
        from every strong pixel no fill has reached (OpenCV's connected components would wake its
        thread pool for every frame, which then spins on the cores the decoding threads need)."""
        mask = (diff > self._core_level).view(np.uint8)
        box = cv2.boundingRect(mask)
        x, y, w, h = box
        rows, cols = diff.shape
        if x > 0 and y > 0 and x + w < cols and y + h < rows and max(w, h) <= self._spread:
            return None, box
        filled = mask.copy()
        if cv2.floodFill(filled, None, top, 2, flags=8)[0] == cv2.countNonZero(mask):
            return None, box
        for index in np.flatnonzero((diff >= self._strong_level) & (filled == 1)):
            seed_y, seed_x = divmod(int(index), cols)
            if filled[seed_y, seed_x] == 1:
                cv2.floodFill(filled, None, (seed_x, seed_y), 2, flags=8)
        kept = (filled == 2).view(np.uint8)
        return kept, cv2.boundingRect(kept)
