"""The analysis chain: frames -> ROIs -> blob tracks -> frame times -> swing signals -> latency.

Most videos are decoded once. Their first frames are held to find the ROIs and their
backgrounds, then every frame is tracked (and its row written to the tracks CSV) as it is decoded;
from then on only the rectangle around both ROIs is decoded (``analysis.video.Crop``). A video
that can skip frames and decode rectangles cheaply (Motion-JPEG) is instead calibrated on a sample
of its first frames and then read again from the start, every frame's rectangle alone. With all
tracks in hand the frame times are decided, the swing frequency and per-period phases are
measured, the whole number of periods in the latency is chosen (``analysis.cycles``), and the
requested estimators run, each taking the same whole number of periods.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import time
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from analysis.cycles import DEFAULT_LATENCY_RANGE_S, CycleResolution, resolve_cycles, unwrap_near
from analysis.errors import AnalysisError
from analysis.onset import departure_time, stop_time
from analysis.phase import estimate_frequency, fft_phase_latency
from analysis.report import TrackStream, write_tracks_csv
from analysis.result import DEFAULT_METHOD, METHODS, LatencyResult, MethodResult
from analysis.signals import SwingSignals, swing_signals
from analysis.timing import check_count, frame_times, implausible_period_warning, repeated_frames
from analysis.tracking import BlobModel, BlobTracker, Detection, Roi, Track, calibrate_blob, find_moving_regions
from analysis.video.file import VideoFile
from analysis.video.frames import Crop, Frame, FrameSource
from analysis.video.sources import open_frames
from analysis.windows import WindowPhases, damping_rate, gain_ratio, window_phases, windowed_latency
from analysis.xcorr import xcorr_latency

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
# until both blobs swing from the start of the frames calibrated on (see _calibration_window), but
# never more than this many bytes of it.
CALIBRATION_MAX_BYTES = 1024 * 2**20
# A track must have a blob in at least this fraction of frames; any frame without one is reported.
MIN_VALID = 0.5
# A blob cut off by its ROI's edge in more than this fraction of frames has left its ROI.
MAX_CLIPPED = 0.1
# Blobs whose typical peaks differ by less than this fraction count as equally bright.
EQUAL_BRIGHTNESS = 0.02
PROGRESS_EVERY = 64
# Clips shorter than this (by their stated length) report no progress: they are done at once.
PROGRESS_MIN_SECONDS = 3.0

BRIGHTER_RULE = "auto: brighter blob is the LED"
LEFT_RULE = "auto: blobs equally bright, left blob is the LED"
SIDES = ("left", "right")
# The swing is analysed up to this long before the first blob stops (a hand slowing the pendulum
# is no free swing).
STOP_MARGIN_S = 0.2
# A blob swings when its place changes by this many times its size, and this many pixels, over
# about SWING_SAMPLES frames.
SWING_SIZES = 2.0
SWING_MIN_PX = 4.0
SWING_SAMPLES = 32


def _side_rule(side: str) -> str:
    return f"given: {side} blob is the LED"


def _auto_models(
    images: Sequence[np.ndarray], led_side: str | None, warnings: list[str]
) -> tuple[BlobModel, BlobModel, str]:
    """LED and sphere models from the two largest moving regions, and the rule that told them apart.

    With ``led_side`` the blob on that side is the LED. Otherwise the brighter blob (higher typical
    peak above its background) is the LED; if both are equally bright (within EQUAL_BRIGHTNESS,
    e.g. both saturated) the left one is.
    """
    regions = find_moving_regions(images)
    if len(regions) < 2:
        raise AnalysisError(
            f"found {len(regions)} moving bright region(s) in the first {len(images)} frames, expected 2 "
            "(the LED and the sphere); check that both are in view and swinging, "
            "or give led_roi and sphere_roi"
        )
    if len(regions) > 2:
        warnings.append(
            f"found {len(regions)} moving regions; used the two largest, "
            f"{regions[0].as_list()} and {regions[1].as_list()}"
        )
    first, second = (calibrate_blob(roi, images, "auto-detected") for roi in regions[:2])
    left, right = (first, second) if first.roi.x <= second.roi.x else (second, first)
    if led_side is not None:
        return (left, right, _side_rule("left")) if led_side == "left" else (right, left, _side_rule("right"))
    brighter, dimmer = (first, second) if first.typical_peak >= second.typical_peak else (second, first)
    if dimmer.typical_peak < (1 - EQUAL_BRIGHTNESS) * brighter.typical_peak:
        return brighter, dimmer, BRIGHTER_RULE
    warnings.append(
        "the two blobs are equally bright; took the left one as the LED. "
        "Give led_side or led_roi and sphere_roi if that is wrong"
    )
    return left, right, LEFT_RULE


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


def _calibration_window(
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


def _bounds(first: Roi, second: Roi) -> tuple[slice, slice]:
    """The rows and columns of the smallest rectangle holding both ROIs: all the tracker looks at,
    so all that is decoded of each frame after calibration."""
    rows = slice(min(first.y, second.y), max(first.y + first.height, second.y + second.height))
    cols = slice(min(first.x, second.x), max(first.x + first.width, second.x + second.width))
    return rows, cols


class _Tracked:
    """Per-frame detections of both blobs, as lists, while the video is read."""

    def __init__(self) -> None:
        self.stamps: list[float] = []
        self.rows: tuple[list[Detection], list[Detection]] = ([], [])

    def track(self, stamp: float, detections: tuple[Detection, Detection]) -> None:
        self.stamps.append(stamp)
        self.rows[0].append(detections[0])
        self.rows[1].append(detections[1])

    def track_of(self, which: int, times: np.ndarray, drop: np.ndarray) -> Track:
        rows = self.rows[which]
        x = np.array([d.x for d in rows], dtype=np.float64)
        y = np.array([d.y for d in rows], dtype=np.float64)
        valid = np.array([d.valid for d in rows], dtype=bool) & ~drop
        return Track(
            t=times,
            x=np.where(valid, x, np.nan),
            y=np.where(valid, y, np.nan),
            valid=valid,
            peak=np.array([d.peak for d in rows], dtype=np.float64),
            clipped=np.array([d.clipped for d in rows], dtype=bool),
        )

    def positions(self, which: int) -> tuple[np.ndarray, np.ndarray]:
        rows = self.rows[which]
        return np.array([d.x for d in rows]), np.array([d.y for d in rows])


def _track_frames(
    frames: Iterable[Frame],
    trackers: tuple[BlobTracker, BlobTracker],
    total: int,
    progress: Callable[[int, int], object] | None,
    stream: TrackStream | None,
) -> _Tracked:
    tracked = _Tracked()
    for index, (stamp, image) in enumerate(frames):
        detections = (trackers[0].locate(image), trackers[1].locate(image))
        tracked.track(stamp, detections)
        if stream is not None:
            stream.write(index, stamp, *detections)
        if progress is not None and (index + 1) % PROGRESS_EVERY == 0:
            progress(index + 1, max(total, index + 1))
    if progress is not None:
        done = len(tracked.stamps)
        progress(done, done)
    return tracked


def _swing_events(
    led: Track, sphere: Track, reference_departures: Mapping[str, float]
) -> tuple[dict[str, float], tuple[float, float]]:
    """Sphere-minus-LED lags of the swing's one-off events (``analysis.cycles``), and the span in
    which both blobs swing freely: from the later departure to the earlier stop less STOP_MARGIN_S."""
    departures = (departure_time(led.t, led.x, led.y), departure_time(sphere.t, sphere.x, sphere.y))
    stops = (stop_time(led.t, led.x, led.y), stop_time(sphere.t, sphere.x, sphere.y))
    events: dict[str, float] = {}
    if departures[1] is not None:
        if departures[0] is not None:
            events["swing start"] = departures[1] - departures[0]
        for name, time in reference_departures.items():
            events[name] = departures[1] - time
    if stops[0] is not None and stops[1] is not None:
        events["swing stop"] = stops[1] - stops[0]
    begin = max((d for d in departures if d is not None), default=-math.inf)
    end = min((s - STOP_MARGIN_S for s in stops if s is not None), default=math.inf)
    return events, (max(begin, float(led.t[0])), min(end, float(led.t[-1])))


def _during(track: Track, span: tuple[float, float]) -> Track:
    """The part of a track inside [start, end]."""
    inside = (track.t >= span[0]) & (track.t <= span[1])
    return Track(**{column.name: getattr(track, column.name)[inside] for column in dataclasses.fields(Track)})


def _checked_track(track: Track, name: str, warnings: list[str]) -> None:
    found = float(np.mean(track.valid))
    clipped = float(np.mean(track.clipped))
    if clipped > MAX_CLIPPED:
        raise AnalysisError(
            f"the {name} leaves its ROI (cut off by its edge) in {clipped:.0%} of frames; "
            f"give a larger {name} ROI that holds its whole swing"
        )
    if found < MIN_VALID:
        raise AnalysisError(
            f"the {name} was found in only {found:.0%} of frames; check that its ROI holds it over "
            "the whole swing and that nothing hides it"
        )
    missing = int(np.count_nonzero(~track.valid))
    if missing:
        # Dark: nothing near the blob's brightness anywhere in the ROI (an LED switched off for a
        # blink code, a hand in front of it), as opposed to a blob seen but not measurable.
        dark = int(np.count_nonzero(~track.valid & ~track.clipped & (track.peak < 0.5 * np.median(track.peak[track.valid]))))
        cut = int(np.count_nonzero(track.clipped))
        reasons = []
        if dark:
            reasons.append(f"{dark} dark (off or hidden)")
        if cut:
            reasons.append(f"{cut} cut off by the ROI's edge")
        detail = f", of them {' and '.join(reasons)}" if reasons else ""
        warnings.append(
            f"the {name} was missing in {missing} frames ({1 - found:.1%}){detail}; those frames were left out"
        )


def _rois(
    video: FrameSource, led_roi: Sequence[float] | None, sphere_roi: Sequence[float] | None
) -> tuple[Roi, Roi] | None:
    if (led_roi is None) != (sphere_roi is None):
        raise AnalysisError("give both led_roi and sphere_roi, or neither to find them automatically")
    if led_roi is None or sphere_roi is None:
        return None
    return Roi.parse(led_roi, video.frame_size, "LED"), Roi.parse(sphere_roi, video.frame_size, "sphere")


def _method_names(method: str) -> tuple[str, ...]:
    if method == "all":
        return METHODS
    if method not in METHODS:
        raise AnalysisError(f"unknown method {method!r}; choose one of {', '.join(METHODS)} or all")
    return (method,)


def _range_s(latency_range_ms: Sequence[float]) -> tuple[float, float]:
    low, high = (float(v) for v in latency_range_ms)
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise AnalysisError(f"latency range {list(latency_range_ms)!r} ms must be two finite numbers, low < high")
    return low / 1e3, high / 1e3


def _estimates(
    names: tuple[str, ...],
    signals: SwingSignals,
    uniform: tuple[np.ndarray, np.ndarray, np.ndarray],
    windows: WindowPhases,
    frequency: float,
    cycles: CycleResolution,
    damping: float,
    seed: int,
    warnings: list[str],
) -> dict[str, MethodResult]:
    """Every requested estimator's result, each unwrapped to the chosen whole number of periods."""
    period = 1.0 / frequency
    results: dict[str, MethodResult] = {}
    _, led, sphere = uniform
    fps = 1.0 / signals.frame_interval
    if "fft" in names:
        started = time.perf_counter()
        estimate = fft_phase_latency(led, sphere, fps, frequency)
        latency = unwrap_near(estimate.latency_s, cycles.reference_s, period)
        results["fft"] = MethodResult(
            "fft", latency * 1e3, None, "sine", time.perf_counter() - started,
            {"frequency_hz": estimate.frequency_hz, "cycles": estimate.cycles},
        )  # fmt: skip
    if "xcorr" in names:
        started = time.perf_counter()
        latency = xcorr_latency(led, sphere, fps, period, cycles.reference_s)
        results["xcorr"] = MethodResult("xcorr", latency * 1e3, None, "sine", time.perf_counter() - started, {})
    if "sinefit" in names or "bayes" in names:
        from analysis.fit.least_squares import Guess, fit_sine

        started = time.perf_counter()
        guess = Guess(frequency, damping, 0.0, cycles.reference_s, gain_ratio(windows))
        fit = fit_sine(signals, (windows.led_noise, windows.sphere_noise), guess)
        if abs(fit.latency_s - cycles.reference_s) > period / 4:
            warnings.append(
                f"the fit moved the latency from {cycles.reference_s * 1e3:.1f} to {fit.latency_s * 1e3:.1f} ms; "
                "check the tracks and the plot"
            )
        if "sinefit" in names:
            results["sinefit"] = MethodResult(
                "sinefit",
                fit.latency_s * 1e3,
                (fit.ci95_s[0] * 1e3, fit.ci95_s[1] * 1e3),
                fit.model,
                time.perf_counter() - started,
                {
                    "se_ms": fit.se_s * 1e3,
                    "se_white_noise_ms": fit.naive_se_s * 1e3,
                    "variance_inflation": fit.lag_inflation,
                    "bic_inflation": fit.inflation,
                    "frequency_hz": fit.frequency_hz,
                    "damping_per_s": fit.damping,
                    "chirp_rad_per_s2": fit.chirp,
                    "gain": fit.gain,
                    "residual_rms_px": {"led": fit.residual_rms_px[0], "sphere": fit.residual_rms_px[1]},
                    "bic": fit.bic,
                    "bic_wald_screened": fit.bic_screened,
                    "iterations": fit.iterations,
                    "frames_per_bin": fit.problem.bins.frames_per_bin,
                },
                fit,
            )
        if "bayes" in names:
            from analysis.fit.posterior import sample_posterior

            started = time.perf_counter()
            posterior = sample_posterior(fit, seed)
            results["bayes"] = MethodResult(
                "bayes",
                posterior.median_s * 1e3,
                (posterior.ci95_s[0] * 1e3, posterior.ci95_s[1] * 1e3),
                fit.model,
                time.perf_counter() - started,
                posterior.details(),
                posterior,
            )
    return results


def analyse(
    source: str | Path | np.ndarray,
    *,
    fps: float | None = None,
    led_roi: Sequence[float] | None = None,
    sphere_roi: Sequence[float] | None = None,
    led_side: str | None = None,
    method: str = DEFAULT_METHOD,
    latency_range_ms: Sequence[float] = tuple(v * 1e3 for v in DEFAULT_LATENCY_RANGE_S),
    progress: Callable[[int, int], object] | None = None,
    tracks_csv: str | Path | None = None,
    seed: int = 0,
    reference_departures: Callable[[Track], Mapping[str, float]] | None = None,
) -> LatencyResult:
    """Measure the latency between the LED and the rendered sphere in a video.

    ``source`` is a video file, a folder of numbered images, or an array of frames, (N, H, W) grey
    or (N, H, W, 3) BGR; ``fps`` overrides the file's frame rate and is required for arrays and
    image folders. ROIs are [x, y, width, height] in pixels: give both or neither; without them the
    two largest moving bright regions are used, the LED being the one on ``led_side`` ("left" or
    "right") if given, else the brighter. ``method`` is one of fft, xcorr, sinefit, bayes, or all
    (every one, sinefit reported first). Latencies are looked for in ``latency_range_ms``.
    ``progress(done, total)`` is called as frames are tracked (for clips of PROGRESS_MIN_SECONDS
    or more); ``tracks_csv`` receives the tracks
    as they are measured. ``seed`` seeds the bayes sampler. ``reference_departures(led_track)``
    names times (s, on the video's clock) at which other instruments saw the pendulum depart from
    rest, in the sense of ``analysis.onset`` (e.g. a rig board's encoder, its clock aligned by the
    LED's blink code, which it reads from the LED track); with the sphere's departure each gives a
    lag that fixes the whole number of periods.
    """
    names = _method_names(method)
    if led_side is not None and led_side not in SIDES:
        raise AnalysisError(f"led_side must be left or right, not {led_side!r}")
    range_s = _range_s(latency_range_ms)
    video = open_frames(source, fps)
    given = _rois(video, led_roi, sphere_roi)
    if video.fps is not None and video.frame_count < PROGRESS_MIN_SECONDS * video.fps:
        progress = None
    warnings: list[str] = []
    started = time.perf_counter()
    crop = Crop()
    rate = video.fps
    wanted = (
        max(CALIBRATION_MIN_FRAMES, round(CALIBRATION_SECONDS * rate)) if rate is not None else CALIBRATION_FRAMES_UNKNOWN_RATE
    )
    every = max(1, wanted // CALIBRATION_SAMPLED_FRAMES) if video.decodes_in_part else 1
    wanted = math.ceil(wanted / every)
    with contextlib.ExitStack() as stack:
        stream = stack.enter_context(contextlib.closing(video.frames(crop, every)))
        rows = stack.enter_context(TrackStream(tracks_csv)) if tracks_csv is not None else None
        first = next(stream)
        window = _calibration_window(first, stream, wanted, CALIBRATION_MAX_BYTES // first[1].nbytes, given)
        images = [image for _, image in window[-wanted:]]
        if given is None:
            led_model, sphere_model, led_rule = _auto_models(images, led_side, warnings)
            roi_source = "auto"
        else:
            led_model = calibrate_blob(given[0], images, "LED")
            sphere_model = calibrate_blob(given[1], images, "sphere")
            roi_source, led_rule = "given", "given"
        del images
        band_rows, band_cols = _bounds(led_model.roi, sphere_model.roi)
        if every > 1:
            stream.close()
            window = []
            stream = stack.enter_context(contextlib.closing(video.frames(crop)))
        crop.to(band_rows, band_cols)
        origin = (band_cols.start, band_rows.start)
        tracked = _track_frames(
            itertools.chain(((stamp, crop.cut(image)) for stamp, image in window), stream),
            (BlobTracker(led_model, origin), BlobTracker(sphere_model, origin)),
            video.frame_count,
            progress,
            rows,
        )
        del window
    track_seconds = time.perf_counter() - started
    analysis_started = time.perf_counter()
    stamps = np.array(tracked.stamps, dtype=np.float64)
    times = frame_times(stamps, video.fps if fps is not None else None, video.container_fps, video.stamp_origin)
    warnings.extend(times.warnings)
    if isinstance(video, VideoFile):
        count_warning = check_count(stamps.size, video.frame_count, video.name)
        if count_warning:
            warnings.append(count_warning)
    repeats = repeated_frames(tracked.positions(0), tracked.positions(1))
    if np.any(repeats):
        warnings.append(
            f"{int(np.count_nonzero(repeats))} frame(s) repeat the one before exactly (inserted by the recorder); "
            "they were left out"
        )
    led_track = tracked.track_of(0, times.t, repeats)
    sphere_track = tracked.track_of(1, times.t, repeats)
    if tracks_csv is not None:
        write_tracks_csv(tracks_csv, led_track, sphere_track)
    _checked_track(led_track, "LED", warnings)
    _checked_track(sphere_track, "sphere", warnings)
    references = reference_departures(led_track) if reference_departures is not None else {}
    events, swinging = _swing_events(led_track, sphere_track, references)
    signals = swing_signals(_during(led_track, swinging), _during(sphere_track, swinging))
    uniform = signals.uniform()
    uniform_fps = 1.0 / signals.frame_interval
    frequency = estimate_frequency(uniform[1], uniform_fps)
    period = 1.0 / frequency
    period_warning = implausible_period_warning(period, times)
    if period_warning:
        warnings.append(period_warning)
    damping = damping_rate(window_phases(signals, frequency))
    windows = window_phases(signals, frequency, damping)
    wrapped = fft_phase_latency(uniform[1], uniform[2], uniform_fps, frequency).latency_s
    cycles = resolve_cycles(wrapped, period, windows, damping, range_s, events)
    if cycles.warning:
        warnings.append(cycles.warning)
    results = _estimates(names, signals, uniform, windows, frequency, cycles, damping, seed, warnings)
    primary = results[names[0] if method != "all" else DEFAULT_METHOD]
    windowed = windowed_latency(windows, primary.latency_ms / 1e3)
    both = led_track.valid & sphere_track.valid
    diagnostics: dict[str, Any] = {
        "time_source": times.source,
        "dropped_frames": times.dropped,
        "repeated_frames": int(np.count_nonzero(repeats)),
        "variable_frame_rate": times.variable,
        "detection_rate": {"led": float(np.mean(led_track.valid)), "sphere": float(np.mean(sphere_track.valid))},
        "clipped_frames": {"led": int(np.count_nonzero(led_track.clipped)), "sphere": int(np.count_nonzero(sphere_track.clipped))},
        "latency_range_ms": [range_s[0] * 1e3, range_s[1] * 1e3],
        "swinging_s": [float(swinging[0]), float(swinging[1])],
        "damping_per_s": damping,
        "track_seconds": track_seconds,
        "estimate_seconds": time.perf_counter() - analysis_started,
    }
    return LatencyResult(
        latency_ms=primary.latency_ms,
        ci95_ms=primary.ci95_ms,
        method=primary.method,
        model=primary.model,
        period_s=period,
        fps=times.fps,
        frames=int(times.t.size),
        frames_used=int(np.count_nonzero(both)),
        ambiguous=cycles.ambiguous,
        warnings=warnings,
        led_roi=led_model.roi,
        sphere_roi=sphere_model.roi,
        roi_source=roi_source,
        led_rule=led_rule,
        methods=results,
        cycles=cycles,
        windowed=windowed,
        diagnostics=diagnostics,
        led_track=led_track,
        sphere_track=sphere_track,
    )
