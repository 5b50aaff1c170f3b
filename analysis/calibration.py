"""The first frames of a video: which of them to hold, and the LED's and the sphere's blob models from them.

Most videos are decoded once: their first frames are held to find the ROIs and their backgrounds
before tracking starts. A video that can skip frames and decode rectangles cheaply (Motion-JPEG) is
instead calibrated on a sample of its first frames, then read again from the start (see
``analysis.tracks``). Without ROIs from the user, the two largest moving bright regions are the
blobs: the LED is the one on the side the user names, or else, provisionally, the left one, until
the whole video's evidence decides (``analysis.identity``, applied by ``analysis.tracks``).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from analysis.caveat import caveat
from analysis.errors import AnalysisError
from analysis.blobs import BlobModel, Roi, calibrate_blob, find_moving_regions
from analysis.video.frames import Frame

# The first frames, up to this long, are held in memory to find the ROIs and their backgrounds
# before tracking starts (so the video is decoded only once)...
CALIBRATION_SECONDS = 1.5
# ...and at least this many frames (a wrong, low frame rate must not starve it), as many when the
# frame rate is not yet known...
CALIBRATION_MIN_FRAMES = 120
CALIBRATION_FRAMES_UNKNOWN_RATE = 360
# ...but where frames left out cost nothing and a crop is decoded alone (Motion-JPEG), every n-th
# frame of those, about this many, is decoded whole and calibrated on, and the video is then read
# again from the start, only the ROIs' rectangle decoded for tracking...
CALIBRATION_SAMPLED_FRAMES = 120
# A clip that starts with the pendulum at rest (a lab films, then releases it) is held further,
# until both blobs swing from the start of the frames calibrated on (see calibration_window), but
# never more than this many bytes of it.
CALIBRATION_MAX_BYTES = 1024 * 2**20
# A blob swings when its place changes by this many times its size, and this many pixels, over
# about SWING_SAMPLES frames.
SWING_SIZES = 2.0
SWING_MIN_PX = 4.0
SWING_SAMPLES = 32

PROVISIONAL_RULE = "auto: left blob, until the evidence decides"


@dataclass(frozen=True)
class Calibration:
    """The LED's and the sphere's blob models, where their ROIs came from ("given" or "auto") and
    the rule that told the LED from the sphere; ``decided`` is False while that is provisional (the
    left blob taken as the LED until the evidence in the whole video decides)."""

    led: BlobModel
    sphere: BlobModel
    roi_source: str
    led_rule: str
    decided: bool = True


def calibration_plan(fps: float | None, decodes_in_part: bool) -> tuple[int, int]:
    """(frames to calibrate on, every how many-th frame they are): CALIBRATION_SECONDS of frames,
    or a sample of about CALIBRATION_SAMPLED_FRAMES of them where frames left out cost nothing."""
    wanted = max(CALIBRATION_MIN_FRAMES, round(CALIBRATION_SECONDS * fps)) if fps is not None else CALIBRATION_FRAMES_UNKNOWN_RATE
    every = max(1, wanted // CALIBRATION_SAMPLED_FRAMES) if decodes_in_part else 1
    return math.ceil(wanted / every), every


def _side_rule(side: str) -> str:
    return f"given: {side} blob is the LED"


def _auto_models(images: Sequence[np.ndarray], led_side: str | None, warnings: list[str]) -> Calibration:
    """LED and sphere models from the two largest moving regions: the LED on ``led_side`` if
    given, else provisionally the left one (not decided)."""
    regions = find_moving_regions(images)
    if len(regions) < 2:
        raise AnalysisError(
            f"found {len(regions)} moving bright region(s) in the first {len(images)} frames, expected 2 "
            "(the LED and the sphere); check that both are in view and swinging, "
            "or give both regions (--led-roi and --sphere-roi)"
        )
    if len(regions) > 2:
        warnings.append(caveat(
            f"found {len(regions)} moving regions, and used the two largest, {regions[0].as_list()} and {regions[1].as_list()}",
            "keep other moving or bright things out of view, or give --led-roi and --sphere-roi",
        ))  # fmt: skip
    first, second = (calibrate_blob(roi, images, "auto-detected") for roi in regions[:2])
    left, right = (first, second) if first.roi.x <= second.roi.x else (second, first)
    if led_side == "right":
        return Calibration(right, left, "auto", _side_rule("right"))
    if led_side == "left":
        return Calibration(left, right, "auto", _side_rule("left"))
    return Calibration(left, right, "auto", PROVISIONAL_RULE, decided=False)


def calibrate(
    images: Sequence[np.ndarray], given: tuple[Roi, Roi] | None, led_side: str | None, warnings: list[str]
) -> Calibration:
    """The blob models from the frames held: in the given (LED, sphere) ROIs, else in the two
    largest moving regions (see ``_auto_models``); warnings about the choice go to ``warnings``."""
    if given is None:
        return _auto_models(images, led_side, warnings)
    return Calibration(calibrate_blob(given[0], images, "LED"), calibrate_blob(given[1], images, "sphere"), "given", "given")


def _swings(crops: Sequence[np.ndarray]) -> bool:
    """Whether the brightest thing in these crops of one region moves by more than twice its size.

    Only frames where it is lit count (at least half its brightest above the region's darkest); in
    each, its place is the centre, and its size the square root of the number, of its pixels above
    half that frame's peak. A blinking LED, or a sphere jittering with the tracker's noise, stays
    within its size; a swinging one does not.
    """
    stack = np.stack(crops)
    lifted = stack - stack.min(axis=0)
    peaks = lifted.max(axis=(1, 2)).astype(np.float64)
    places, sizes = [], []
    for image, peak in zip(lifted, peaks):
        if peak > 0 and peak >= 0.5 * peaks.max():
            moments = cv2.moments((image >= 0.5 * peak).view(np.uint8), binaryImage=True)
            places.append((moments["m10"] / moments["m00"], moments["m01"] / moments["m00"]))
            sizes.append(math.sqrt(moments["m00"]))
    if len(places) < 2:
        return False
    travel = float(np.max(np.ptp(np.array(places), axis=0)))
    return travel >= max(SWING_MIN_PX, SWING_SIZES * float(np.median(sizes)))


def _shows_motion(images: Sequence[np.ndarray], given: tuple[Roi, Roi] | None) -> bool:
    """Whether both blobs swing in these frames: in the given ROIs, or in the two largest moving
    regions (those ``_auto_models`` takes)."""
    samples = images[:: max(1, len(images) // SWING_SAMPLES)]
    regions = list(given) if given is not None else find_moving_regions(samples)[:2]
    return len(regions) == 2 and all(_swings([region.crop(image) for image in samples]) for region in regions)


def calibration_window(
    first: Frame, stream: Iterator[Frame], wanted: int, most: int, given: tuple[Roi, Roi] | None
) -> list[Frame]:
    """The first frames, held to calibrate on their last ``wanted``: ``wanted`` of them, or more,
    half ``wanted`` at a time, up to ``most`` frames, while the first quarter of those last frames
    does not show both blobs move (the pendulum was held still, or not yet the sphere). A blob must
    move in most calibration frames for their median to be its background."""
    window = [first, *itertools.islice(stream, max(2, min(wanted, most)) - 1)]
    while len(window) < most and not _shows_motion([image for _, image in window[-wanted:][: max(wanted // 4, 2)]], given):
        more = list(itertools.islice(stream, min(max(wanted // 2, 1), most - len(window))))
        if not more:
            break
        window.extend(more)
    return window
