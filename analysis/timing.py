"""When each frame was taken: container timestamps where they can be trusted, else the frame rate.

A container's timestamps are trusted when they increase: they are fitted by a constant rate with
gaps, each frame on a "slot" round((stamp - first) / interval), the interval being the stated
frame rate's or else the median step. If every stamp lies within
STAMP_JITTER of its slot (timestamps rounded to the millisecond, as Matroska stores them, pass),
the video has a constant frame rate, missing slots are dropped frames, and frame times are the
slots times the interval. Otherwise the rate is variable and the stamps themselves are the times.

A frame rate the user gives rescales the times (the container's rate is then only a unit): phone
slow-motion files often state their playback rate, not their capture rate. Without usable stamps,
frame i is at i / fps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.caveat import caveat
from analysis.errors import AnalysisError

# A stamp this far from its constant-rate slot (fraction of the interval, or absolute seconds,
# whichever is larger) makes the frame rate variable.
STAMP_JITTER_FRACTION = 0.25
STAMP_JITTER_S = 0.0006
# Swing periods of lab pendulums (1 cm to 6 m long); others suggest a wrong frame rate.
PLAUSIBLE_PERIOD_S = (0.2, 5.0)
# The container's stated rate and its timestamps may differ by this fraction before a warning.
RATE_AGREEMENT = 0.01


@dataclass(frozen=True)
class FrameTimes:
    """Frame times in seconds from the first frame, the frame rate they imply, and how they were found."""

    t: np.ndarray
    fps: float
    source: str
    dropped: int
    variable: bool
    warnings: list[str]


def _uniform(count: int, fps: float, source: str, warnings: list[str]) -> FrameTimes:
    return FrameTimes(np.arange(count, dtype=np.float64) / fps, fps, source, 0, False, warnings)


def frame_times(
    stamps: np.ndarray, user_fps: float | None, stated_fps: float | None, stamp_origin: str
) -> FrameTimes:
    """The times of frames whose source recorded ``stamps`` (s, NaN where unknown).

    ``user_fps`` is the rate the user gave, ``stated_fps`` what the file says (None if nothing or
    nothing plausible); ``stamp_origin`` names where the stamps come from ("container", "image
    numbers", "array index"). Raises AnalysisError when no rate is known at all.
    """
    count = stamps.size
    warnings: list[str] = []
    rate = user_fps if user_fps is not None else stated_fps
    usable = count >= 2 and bool(np.all(np.isfinite(stamps))) and bool(np.all(np.diff(stamps) > 0))
    if not usable:
        if rate is None:
            raise AnalysisError(
                "no frame rate is known: the file states none that is plausible and its timestamps are "
                "unusable; pass --fps (fps=) with the camera's frame rate"
            )
        if count >= 2 and np.all(np.isfinite(stamps)):
            warnings.append(caveat(
                f"the {stamp_origin} timestamps do not increase, so frame i was taken at i / {rate:g} fps",
                "give --fps with the camera's frame rate if that is not it, or film with an app that stamps each frame",
            ))  # fmt: skip
        return _uniform(count, rate, "frame rate given" if user_fps is not None else "stated frame rate", warnings)

    relative = stamps - stamps[0]
    median = float(np.median(np.diff(relative)))
    # The stated interval first: stamps rounded to the millisecond have a misleading median step.
    guesses = ([1.0 / stated_fps] if stated_fps is not None else []) + [median]
    for interval in guesses:
        slots = np.rint(relative / interval)
        slope = float(np.dot(slots, relative) / np.dot(slots, slots))
        jitter = float(np.max(np.abs(relative - slots * slope)))
        constant = bool(np.all(np.diff(slots) > 0)) and jitter <= max(STAMP_JITTER_FRACTION * slope, STAMP_JITTER_S)
        if constant:
            break
    stamp_fps = 1.0 / slope if constant else 1.0 / median
    if stated_fps is not None and abs(stamp_fps - stated_fps) > RATE_AGREEMENT * stated_fps:
        warnings.append(caveat(
            f"the file states {stated_fps:g} fps but its timestamps are {stamp_fps:.4g} fps apart, and the timestamps "
            f"were used{'' if user_fps is None else ' (rescaled to the frame rate given)'}",
            "give --fps with the camera's true frame rate if the timestamps are wrong",
        ))  # fmt: skip
    dropped = int(slots[-1]) - (count - 1) if constant else 0
    if dropped > 0:
        warnings.append(caveat(
            f"{dropped} frame(s) were dropped by the recorder (gaps in the {stamp_origin} timestamps); the analysis "
            "used the true frame times",
            "film at a rate, size or quality the recorder keeps up with, so that it keeps every frame",
        ))  # fmt: skip
    if not constant:
        warnings.append(caveat(
            f"the frame rate varies (timestamps stray up to {jitter * 1e3:.2f} ms from a constant rate), so each "
            "frame's time was taken from its timestamp",
            "fix the camera's frame rate and exposure (no automatic modes) if the timestamps may be wrong",
        ))  # fmt: skip
    unit = stamp_fps / user_fps if user_fps is not None else 1.0
    times = (slots * slope if constant else relative) * unit
    fps = user_fps if user_fps is not None else stamp_fps
    rescaled = abs(unit - 1.0) > 1e-9
    source = f"{stamp_origin} timestamps" + (f", rescaled to {user_fps:g} fps" if rescaled else "")
    return FrameTimes(times, fps, source, dropped, not constant, warnings)


def implausible_period_warning(period_s: float, times: FrameTimes) -> str | None:
    """A warning when the swing period found is unlike any lab pendulum's: a sign of a wrong frame rate."""
    low, high = PLAUSIBLE_PERIOD_S
    if low <= period_s <= high:
        return None
    return caveat(
        f"the pendulum period comes out as {period_s:.3g} s at {times.fps:g} fps ({times.source}), unlike any lab "
        "pendulum's: the frame rate may be wrong",
        "if the video is slow motion or its frame rate is wrong, give --fps with the rate it was filmed at",
    )


def recorder_repeats(whole: np.ndarray, times: FrameTimes) -> np.ndarray:
    """Frames the recorder repeated (bool per frame): each whole frame that is the one before
    exactly (``whole``, noted by the source), where the frame times confirm a copy.

    With sensor noise no two captures are identical, so an identical whole frame is a copy the
    recorder put in a slot of a constant frame rate for want of a new one; its time is wrong. Only
    the whole frame counts: an encoder keeps still regions of a compressed film bit for bit while
    the rest changes. Where the file stamps each frame with its own time and those times vary (as
    phones record), a recorder that misses a capture leaves a gap, not a copy: an identical frame
    there is a capture at its own time (a still scene, or one its encoder found unchanged), and is
    kept.
    """
    if times.variable:
        return np.zeros(whole.shape, dtype=bool)
    return whole.astype(bool, copy=True)


def check_count(decoded: int, stated: int, name: str) -> str | None:
    """A warning when a file decodes to a different number of frames than its container states."""
    if stated <= 0 or abs(decoded - stated) <= max(1, math.ceil(0.001 * stated)):
        return None
    return caveat(
        f"{name} states {stated} frames but {decoded} were decoded, so its metadata may be wrong",
        "check the frame count and rate the camera reports, or record the film again",
    )
