"""The analysis chain: frames -> ROIs -> blob tracks -> axis signals -> latency."""

from __future__ import annotations

import contextlib
import itertools
import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from analysis.errors import AnalysisError
from analysis.phase import axis_signal, fft_phase_latency
from analysis.result import LatencyResult, is_ambiguous
from analysis.tracking import BlobModel, Roi, Track, calibrate_blob, find_moving_regions, track_blobs
from analysis.video import open_frames

# The first frames, up to this long, are held in memory to find the ROIs and their backgrounds
# before tracking starts (so the video is decoded only once)...
CALIBRATION_SECONDS = 1.5
# ...but never more than this many bytes of them.
CALIBRATION_MAX_BYTES = 256 * 2**20
# A track must have a blob in at least this fraction of frames; any frame without one is reported.
MIN_VALID = 0.5
# Blobs whose typical peaks differ by less than this fraction count as equally bright.
EQUAL_BRIGHTNESS = 0.02

BRIGHTER_RULE = "auto: brighter blob is the LED"
LEFT_RULE = "auto: blobs equally bright, left blob is the LED"


def _auto_models(window: Sequence[np.ndarray], warnings: list[str]) -> tuple[BlobModel, BlobModel, str]:
    """LED and sphere models from the two largest moving regions, and the rule that told them apart.

    The brighter blob (higher typical peak above its background) is the LED; if both are equally
    bright (within EQUAL_BRIGHTNESS, e.g. both saturated) the left one is.
    """
    regions = find_moving_regions(window)
    if len(regions) < 2:
        raise AnalysisError(
            f"found {len(regions)} moving bright region(s) in the first {len(window)} frames, expected 2 "
            "(the LED and the sphere); check that both are in view and swinging, "
            "or give led_roi and sphere_roi"
        )
    if len(regions) > 2:
        warnings.append(
            f"found {len(regions)} moving regions; used the two largest, "
            f"{regions[0].as_list()} and {regions[1].as_list()}"
        )
    first, second = (calibrate_blob(roi, window, "auto-detected") for roi in regions[:2])
    brighter, dimmer = (first, second) if first.typical_peak >= second.typical_peak else (second, first)
    if dimmer.typical_peak < (1 - EQUAL_BRIGHTNESS) * brighter.typical_peak:
        return brighter, dimmer, BRIGHTER_RULE
    warnings.append(
        "the two blobs are equally bright; took the left one as the LED. "
        "Give led_roi and sphere_roi if that is wrong"
    )
    left, right = (first, second) if first.roi.x <= second.roi.x else (second, first)
    return left, right, LEFT_RULE


def _checked_track(track: Track, name: str, warnings: list[str]) -> None:
    found = float(np.mean(track.valid))
    missing = int(np.count_nonzero(~track.valid))
    if found < MIN_VALID:
        raise AnalysisError(
            f"the {name} was found in only {found:.0%} of frames; check that its ROI holds it over "
            "the whole swing and that nothing hides it"
        )
    if missing:
        warnings.append(
            f"the {name} was missing in {missing} frames ({1 - found:.1%}); "
            "its position there was interpolated"
        )


def analyse(
    source: str | Path | np.ndarray,
    *,
    fps: float | None = None,
    led_roi: Sequence[float] | None = None,
    sphere_roi: Sequence[float] | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> LatencyResult:
    """Measure the latency between the LED and the rendered sphere in a video.

    ``source`` is a video file or an array of frames, (N, H, W) grey or (N, H, W, 3) BGR; ``fps``
    overrides the file's frame rate and is required for arrays. ROIs are [x, y, width, height] in
    pixels: give both or neither; without them the two largest moving bright regions are used and
    the brighter is taken as the LED. ``progress(done, total)`` is called as frames are tracked.
    """
    video = open_frames(source, fps)
    if (led_roi is None) != (sphere_roi is None):
        raise AnalysisError("give both led_roi and sphere_roi, or neither to find them automatically")
    given = (
        None
        if led_roi is None or sphere_roi is None
        else (Roi.parse(led_roi, video.frame_size, "LED"), Roi.parse(sphere_roi, video.frame_size, "sphere"))
    )
    warnings: list[str] = []
    with contextlib.closing(video.frames()) as stream:
        first = next(stream)
        window_size = max(
            2, min(round(CALIBRATION_SECONDS * video.fps), CALIBRATION_MAX_BYTES // first.nbytes)
        )
        window = [first, *itertools.islice(stream, window_size - 1)]
        if given is None:
            led_model, sphere_model, led_rule = _auto_models(window, warnings)
            roi_source = "auto"
        else:
            led_model = calibrate_blob(given[0], window, "LED")
            sphere_model = calibrate_blob(given[1], window, "sphere")
            roi_source, led_rule = "given", "given"
        led_track, sphere_track = track_blobs(
            itertools.chain(window, stream), (led_model, sphere_model), video.fps, video.frame_count, progress
        )
    _checked_track(led_track, "LED", warnings)
    _checked_track(sphere_track, "sphere", warnings)
    estimate = fft_phase_latency(
        axis_signal(led_track, "LED"), axis_signal(sphere_track, "sphere"), video.fps
    )
    period_s = 1.0 / estimate.frequency_hz
    ambiguous = is_ambiguous(estimate.latency_s, period_s)
    if ambiguous:
        other_ms = (estimate.latency_s - math.copysign(period_s, estimate.latency_s)) * 1e3
        warnings.append(
            f"the latency is near half the period ({period_s / 2 * 1e3:.1f} ms), where the phase wraps; "
            f"it may really be {other_ms:.1f} ms"
        )
    return LatencyResult(
        latency_ms=estimate.latency_s * 1e3,
        ci95_ms=None,
        method="fft",
        model="sine",
        period_s=period_s,
        fps=video.fps,
        frames=int(led_track.t.size),
        frames_used=int(np.count_nonzero(led_track.valid & sphere_track.valid)),
        ambiguous=ambiguous,
        warnings=warnings,
        led_roi=led_model.roi,
        sphere_roi=sphere_model.roi,
        roi_source=roi_source,
        led_rule=led_rule,
        led_track=led_track,
        sphere_track=sphere_track,
    )
