"""A film of a flashing light reduced to what the shutter estimator needs: each row's level in each frame.

The film is read twice. The first pass finds, pixel by pixel, how far its level swings between
frames: the pixels the flashing light reaches swing by at least LIT_SHARE of the film's largest
swing, and those that reach SATURATED_DN in any frame are left out (a clipped pixel's level is
not the share of its exposure the light was on). The second pass averages each row's usable
pixels in every frame. A row's level is then its dark level plus its own gain times the share of
its exposure the light was on, whatever the light's shape and vignetting, so rows need not be
lit alike, and the light may cover only part of the frame.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from analysis.errors import AnalysisError
from analysis.timing import frame_times
from analysis.video.frames import Crop
from analysis.video.sources import open_frames

# A pixel is lit when its level swings by this share of the film's largest swing (its 99.5th
# percentile over pixels), which must be at least MIN_SWING_DN.
LIT_SHARE = 0.35
LARGEST_SWING_PERCENTILE = 99.5
MIN_SWING_DN = 8.0
# An 8-bit level this high is taken as clipped.
SATURATED_DN = 254.0
# The lit area's columns are those the light reaches in at least this share of the rows it reaches
# most; its rows are inside while their swing over those columns is at least this share of the
# median inside row's (where a display's panel begins and ends).
EDGE_SHARE = 0.5
# Beyond the inside rows, this many are looked at for a partly lit edge (blur, a row half covered).
EDGE_REACH = 6
# Rows beyond this many frame-row samples are thinned, every n-th row kept (thinning, unlike
# averaging neighbours, keeps each row's exposure window exact).
MAX_SAMPLES = 300_000

Rect = tuple[int, int, int, int]
Progress = Callable[[int, int], object]


@dataclass(frozen=True)
class RowFilm:
    """Each used row's mean level in each frame, and where it came from.

    levels (frames, rows) the mean of each row's usable pixels; rows their indices in the whole
    frame, pixels how many were averaged; times each frame's time (s); height the whole frame's
    rows; edges where the lit area begins and ends, in rows of the whole frame from its top (the light
reaches rows edges[0] to edges[1], fractions of a row where it covers part of one); region
    the rectangle searched (x, y, w, h); lit and saturated the pixels the light reaches and those
    left out for clipping.
    """

    levels: np.ndarray
    rows: np.ndarray
    pixels: np.ndarray
    times: np.ndarray
    height: int
    edges: tuple[float, float]
    region: Rect
    lit: int
    saturated: int
    timing_source: str
    warnings: tuple[str, ...] = ()

    @property
    def frame_interval_s(self) -> float:
        """The time between frames (s): their mean step, or the median where frames are missing."""
        steps = np.diff(self.times)
        median = float(np.median(steps))
        return float(np.mean(steps)) if np.max(steps) < 1.5 * median else median


def read_film(video: str | Path | np.ndarray, fps: float | None = None, roi: Rect | None = None,
              progress: Progress | None = None) -> RowFilm:  # fmt: skip
    """A video file, a folder of numbered images or an (N, H, W) array, within ``roi`` (x, y, w,
    h pixels; the whole frame when None), as rows; frame times from the file's timestamps where
    they can be trusted (``analysis.timing``), ``fps`` overriding its rate."""
    source = open_frames(video, fps)
    width, height = source.frame_size
    region = _region(roi, width, height)
    x, y, w, h = region
    count = max(source.frame_count, 1)
    stamps: list[float] = []

    def frames() -> Iterator[np.ndarray]:
        crop = Crop()
        crop.to(slice(y, y + h), slice(x, x + w))
        first = not stamps
        for index, (stamp, frame) in enumerate(source.frames(crop)):
            if first:
                stamps.append(stamp)
            if progress is not None:
                progress(index + (0 if first else count), 2 * count)
            yield frame

    def timing() -> tuple[np.ndarray, str, list[str]]:
        return _film_times(np.array(stamps), fps, source.container_fps, source.stamp_origin)

    return _rows_of(frames, timing, (width, height), region)


def _film_times(stamps: np.ndarray, fps: float | None, stated_fps: float | None, origin: str) -> tuple[np.ndarray, str, list[str]]:
    """The frames' times, their source and warnings: ``analysis.timing``'s, except that stamps
    within a quarter frame of a constant rate are kept as recorded, rescaled alike, unless they are
    rounded to whole milliseconds. The bands time each frame to a small share of the exposure, so a
    phone's own capture jitter matters here where the latency analysis may snap it to the rate."""
    times = frame_times(stamps, fps, stated_fps, origin)
    relative = stamps - stamps[0]
    rounded = bool(np.all(np.abs(stamps * 1e3 - np.rint(stamps * 1e3)) < 1e-6))
    if times.variable or rounded or not relative[-1] > 0:
        return times.t, times.source, times.warnings
    return relative * (times.t[-1] / relative[-1]), f"{times.source}, as recorded", times.warnings


def film_of_frames(frames: np.ndarray, times: np.ndarray, roi: Rect | None = None) -> RowFilm:
    """Frames held in memory, (N, H, W) levels, taken at ``times`` (s), within ``roi``, as rows."""
    if frames.ndim != 3 or len(times) != len(frames):
        raise AnalysisError(f"give frames as (N, H, W) levels with one time each, not {frames.shape} and {len(times)} times")
    height, width = frames.shape[1:]
    x, y, w, h = region = _region(roi, width, height)
    times = np.asarray(times, dtype=np.float64)
    return _rows_of(lambda: iter(frames[:, y : y + h, x : x + w]), lambda: (times, "times given", []), (width, height), region)


def _region(roi: Rect | None, width: int, height: int) -> Rect:
    if roi is None:
        return (0, 0, width, height)
    x, y, w, h = roi
    if x < 0 or y < 0 or w <= 0 or h <= 0 or x + w > width or y + h > height:
        raise AnalysisError(f"the region {x},{y},{w},{h} does not lie within the {width}x{height} frame; give --roi X,Y,W,H inside it")
    return roi


def _rows_of(frames: Callable[[], Iterable[np.ndarray]], timing: Callable[[], tuple[np.ndarray, str, list[str]]],
             size: tuple[int, int], region: Rect) -> RowFilm:  # fmt: skip
    low, high, count = _extremes(frames())
    times, timing_source, warnings = timing()
    swing = high - low
    largest = float(np.percentile(swing, LARGEST_SWING_PERCENTILE))
    where = "the frame" if region == (0, 0, *size) else f"the region {','.join(map(str, region))}"
    if largest < MIN_SWING_DN:
        raise AnalysisError(
            f"no flashing light found in {where}: no pixel's level swings by more than {largest:.0f} of 255 between "
            "frames; film the light flashing (at a frequency that is no multiple of the frame rate, at which it looks "
            "still), brighter, or give --roi around it"
        )
    lit = swing >= LIT_SHARE * largest
    usable = lit & (high < SATURATED_DN)
    lit_per_row, usable_per_row = lit.sum(axis=1), usable.sum(axis=1)
    if not usable_per_row.any():
        raise AnalysisError(
            f"the light saturates all {int(lit.sum())} pixels it reaches: dim the light or lower the camera's gain "
            "(keep the exposure you want to calibrate)"
        )
    used = np.flatnonzero(usable_per_row)
    every = max(1, math.ceil(count * len(used) / MAX_SAMPLES))
    used = used[::every]
    levels = _row_means(frames(), usable[used], used)
    top = region[1]
    return RowFilm(
        levels=levels,
        rows=used + top,
        pixels=usable_per_row[used],
        times=times,
        height=size[1],
        edges=_edges(swing, lit, top),
        region=region,
        lit=int(lit.sum()),
        saturated=int(lit.sum() - usable.sum()),
        timing_source=timing_source,
        warnings=tuple(warnings),
    )


def _extremes(frames: Iterable[np.ndarray]) -> tuple[np.ndarray, np.ndarray, int]:
    """Each pixel's lowest and highest level over the frames, and how many frames there were."""
    low = high = None
    count = 0
    for frame in frames:
        grey = frame.astype(np.float32, copy=False)
        if low is None or high is None:
            low, high = grey.copy(), grey.copy()
        else:
            np.minimum(low, grey, out=low)
            np.maximum(high, grey, out=high)
        count += 1
    if low is None or high is None:
        raise AnalysisError("the film has no frames; film the flashing light for a few seconds")
    return low, high, count


def _row_means(frames: Iterable[np.ndarray], mask: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Each of ``rows``' mean over its ``mask`` pixels, frame by frame: (frames, rows)."""
    weights = mask.astype(np.float64) / mask.sum(axis=1, keepdims=True)
    return np.array([np.einsum("yx,yx->y", frame[rows].astype(np.float64, copy=False), weights) for frame in frames])


def _edges(swing: np.ndarray, lit: np.ndarray, top: int) -> tuple[float, float]:
    """Where the lit area begins and ends (rows of the whole frame, fractional). From a row
    EDGE_REACH rows inside each edge, the edge lies as many rows out as the rows' shares of light
    over the next 2 EDGE_REACH rows outwards add up to: each row's share its swing (over the lit
    columns, less the unlit rows' swing, sensor noise) over that of the rows just inside it. Blur
    spreads an edge over rows but keeps that sum."""
    columns = lit.sum(axis=0) >= EDGE_SHARE * lit.sum(axis=0).max()
    profile = swing[:, columns].mean(axis=1)
    outside = ~lit[:, columns].any(axis=1)
    profile = profile - (np.median(profile[outside]) if outside.any() else 0.0)
    inside = np.flatnonzero(profile >= EDGE_SHARE * np.median(profile[profile >= EDGE_SHARE * profile.max()]))
    first, last = int(inside[0]), int(inside[-1])
    reach = max(1, min(EDGE_REACH, (last - first) // 4))

    def shares(anchor: int, step: int) -> float:  # from the anchor row outwards
        level = float(np.median(profile[anchor : anchor - 3 * step : -step]))
        rows = anchor + step * np.arange(1, 2 * reach + 1)
        rows = rows[(rows >= 0) & (rows < len(profile))]
        return float(np.clip(profile[rows] / max(level, 1e-9), 0.0, 1.0).sum())

    return top + first + reach - shares(first + reach, -1), top + last - reach + 1 + shares(last - reach, 1)
