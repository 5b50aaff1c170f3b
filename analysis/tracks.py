"""The first part of an analysis: a video in, both blobs' tracks out (``track`` -> ``Tracks``).

Most videos are decoded once. Their first frames are held to find the ROIs and their backgrounds
(``analysis.calibration``), then every frame is tracked (and its row written to the tracks CSV) as
it is decoded; from then on only the rectangle around both ROIs is decoded
(``analysis.video.frames.Crop``). A video that can skip frames and decode rectangles cheaply
(Motion-JPEG) is instead calibrated on a sample of its first frames and then read again from the
start, every frame's rectangle alone. With all detections in hand the frame times are decided
(``analysis.timing``), frames the recorder repeated (whole frames, noted by the source as it
reads) are left out, and so are frames in which a
blob shows much less of its light than usual (partly hidden: its centroid is not its centre).
Where neither the user's ROIs nor a side said which blob is the LED, the whole video's evidence
decides (``analysis.identity``); when it does not, the analysis stops and asks for the ROIs. Then
each track is checked.
"""

from __future__ import annotations

import contextlib
import dataclasses
import itertools
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from analysis.calibration import (
    CALIBRATION_MAX_BYTES,
    Calibration,
    calibrate,
    calibration_plan,
    calibration_window,
)
from analysis.caveat import caveat
from analysis.errors import AnalysisError
from analysis.identity import Identity, identify
from analysis.options import AnalysisOptions
from analysis.timing import FrameTimes, check_count, frame_times, recorder_repeats
from analysis.blobs import BlobTracker, Detection, Roi, Track
from analysis.tracks_csv import TrackStream, write_tracks_csv
from analysis.video.file import VideoFile
from analysis.video.frames import Crop, Frame, FrameSource, Repeats
from analysis.video.sources import open_frames

# A track must have a blob in at least this fraction of frames; any frame without one is reported.
MIN_VALID = 0.5
# A blob cut off by its ROI's edge in more than this fraction of frames has left its ROI.
MAX_CLIPPED = 0.1
# A blob showing less than this fraction of its median summed light is partly hidden.
MIN_LIGHT = 0.7
PROGRESS_EVERY = 64
# Clips shorter than this (by their stated length) report no progress: they are done at once.
PROGRESS_MIN_SECONDS = 3.0


@dataclass(frozen=True)
class Tracks:
    """Both blobs' tracks in one video and how they were found: what ``track`` gives ``estimate``.

    stamps holds each frame's time as the source recorded it (s, NaN where none); ``times`` the
    frame times decided from them, which are the tracks' t. roi_source says where the ROIs came
    from ("given" or "auto"), led_rule how the LED was told from the sphere. warnings are for the
    user, in the order they arose; diagnostics are JSON-ready facts about the reading (time source,
    dropped and repeated frames, detection rates, clipped frames); seconds is how long reading and
    tracking took; frame_size the frames' (width, height) in pixels.
    """

    led: Track
    sphere: Track
    stamps: np.ndarray
    times: FrameTimes
    led_roi: Roi
    sphere_roi: Roi
    roi_source: str
    led_rule: str
    warnings: tuple[str, ...]
    diagnostics: dict[str, Any]
    seconds: float
    frame_size: tuple[int, int]

    def write_csv(self, path: str | Path) -> None:
        """Write both tracks to a CSV file, one row per frame (``analysis.tracks_csv``)."""
        write_tracks_csv(path, self.stamps, self.led, self.sphere)


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
        """The track of one blob; frames in ``drop``, and frames where it is partly hidden, are not valid."""
        rows = self.rows[which]
        x = np.array([d.x for d in rows], dtype=np.float64)
        y = np.array([d.y for d in rows], dtype=np.float64)
        mass = np.array([d.mass for d in rows], dtype=np.float64)
        valid = np.array([d.valid for d in rows], dtype=bool) & ~drop
        if np.any(valid):
            valid &= mass >= MIN_LIGHT * float(np.median(mass[valid]))
        spread = np.array([(d.sxx, d.syy, d.sxy) for d in rows], dtype=np.float64).reshape(-1, 3)
        return Track(
            t=times,
            x=np.where(valid, x, np.nan),
            y=np.where(valid, y, np.nan),
            valid=valid,
            peak=np.array([d.peak for d in rows], dtype=np.float64),
            clipped=np.array([d.clipped for d in rows], dtype=bool),
            level=np.array([d.level for d in rows], dtype=np.float64),
            mass=mass,
            spread=np.where(valid[:, None], spread, np.nan),
        )


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


def _bounds(first: Roi, second: Roi) -> tuple[slice, slice]:
    """The rows and columns of the smallest rectangle holding both ROIs: all the tracker looks at,
    so all that is decoded of each frame after calibration."""
    rows = slice(min(first.y, second.y), max(first.y + first.height, second.y + second.height))
    cols = slice(min(first.x, second.x), max(first.x + first.width, second.x + second.width))
    return rows, cols


def _read(
    video: FrameSource,
    given: tuple[Roi, Roi] | None,
    led_side: str | None,
    progress: Callable[[int, int], object] | None,
    tracks_csv: str | Path | None,
    warnings: list[str],
    repeats: Repeats,
) -> tuple[Calibration, _Tracked]:
    """Calibrate on the first frames, then track every frame, each row going to ``tracks_csv`` as
    it is measured (see the module docstring); the source notes whole repeated frames in ``repeats``."""
    crop = Crop()
    wanted, every = calibration_plan(video.fps, video.decodes_in_part)
    with contextlib.ExitStack() as stack:
        stream = stack.enter_context(contextlib.closing(video.frames(crop, every, repeats)))
        rows = stack.enter_context(TrackStream(tracks_csv)) if tracks_csv is not None else None
        first = next(stream)
        window = calibration_window(first, stream, wanted, CALIBRATION_MAX_BYTES // first[1].nbytes, given)
        calibration = calibrate([image for _, image in window[-wanted:]], given, led_side, warnings)
        band_rows, band_cols = _bounds(calibration.led.roi, calibration.sphere.roi)
        if every > 1:
            stream.close()
            window = []
            stream = stack.enter_context(contextlib.closing(video.frames(crop, repeats=repeats)))
        crop.to(band_rows, band_cols)
        origin = (band_cols.start, band_rows.start)
        tracked = _track_frames(
            itertools.chain(((stamp, crop.cut(image)) for stamp, image in window), stream),
            (BlobTracker(calibration.led, origin), BlobTracker(calibration.sphere, origin)),
            video.frame_count,
            progress,
            rows,
        )
    return calibration, tracked


def check_track(track: Track, name: str, warnings: list[str]) -> None:
    """AnalysisError if the blob left its ROI or was found too rarely; else a warning for any frames
    it is missing in, saying how many were dark and how many cut off."""
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
        remedies = [f"keep the {name} lit and in view while filming"] if dark or not cut else []
        remedies += [f"give a larger {name} ROI that holds its whole swing"] if cut else []
        warnings.append(caveat(
            f"the {name} was missing in {missing} frames ({1 - found:.1%}){detail}; those frames were left out",
            ", and ".join(remedies),
        ))  # fmt: skip


def _identity(first: Track, second: Track, fps: float) -> Identity:
    """Which of the two blobs is the LED (``analysis.identity``); AnalysisError when the evidence
    does not decide, which names the evidence and asks for the regions."""
    identity = identify(first, second)
    if identity.first_is_led is None:
        evidence = ", ".join(f"{name} {value:+.1f}" for name, value in identity.evidence.items())
        raise AnalysisError(
            "cannot tell the LED from the sphere: the evidence (log-odds that the left blob is the LED: "
            f"{evidence}; total {identity.margin:+.1f}) does not decide. Give the LED's and the sphere's regions "
            "(led_roi and sphere_roi; --led-roi X,Y,W,H --sphere-roi X,Y,W,H on the command line) or the LED's "
            "side (led_side, --led-side)"
        )
    return identity


def _rois(
    video: FrameSource, led_roi: Sequence[float] | None, sphere_roi: Sequence[float] | None
) -> tuple[Roi, Roi] | None:
    if (led_roi is None) != (sphere_roi is None):
        raise AnalysisError("give both regions, the LED's and the sphere's (--led-roi and --sphere-roi), or neither to find them automatically")
    if led_roi is None or sphere_roi is None:
        return None
    return Roi.parse(led_roi, video.frame_size, "LED"), Roi.parse(sphere_roi, video.frame_size, "sphere")


def track(
    source: str | Path | np.ndarray,
    options: AnalysisOptions = AnalysisOptions(),
    *,
    progress: Callable[[int, int], object] | None = None,
    tracks_csv: str | Path | None = None,
) -> Tracks:
    """Track the LED and the rendered sphere in every frame of a video.

    ``source`` is a video file, a folder of numbered images, or an array of frames, (N, H, W) grey
    or (N, H, W, 3) BGR. Of the ``options``, ``fps`` overrides the file's frame rate and is required
    for arrays and image folders; the ROIs are [x, y, width, height] in pixels: give both or
    neither; without them the two largest moving bright regions are used, the LED being the one on
    ``led_side`` ("left" or "right") if given, else the one the physical evidence names
    (``analysis.identity``; an AnalysisError asks for the ROIs when it does not decide); the regions
    and the side may come from the options' hints (``AnalysisOptions.hinted``), which ``estimate``
    checks against the video. ``progress(done, total)`` is called
    as frames are tracked (for clips of PROGRESS_MIN_SECONDS or more). ``tracks_csv`` receives
    every frame's row as it is measured (the left blob first as the LED while that is undecided),
    then the final table once the frame times are decided (``analysis.tracks_csv``); it is
    written before the tracks are checked, so tracks that fail a check stay on disk to look at.
    """
    options = options.hinted()
    fps = options.fps
    video = open_frames(source, fps)
    given = _rois(video, options.led_roi, options.sphere_roi)
    if video.fps is not None and video.frame_count < PROGRESS_MIN_SECONDS * video.fps:
        progress = None
    warnings: list[str] = []
    started = time.perf_counter()
    noted = Repeats()
    calibration, tracked = _read(video, given, options.led_side, progress, tracks_csv, warnings, noted)
    seconds = time.perf_counter() - started
    stamps = np.array(tracked.stamps, dtype=np.float64)
    times = frame_times(stamps, video.fps if fps is not None else None, video.container_fps, video.stamp_origin)
    warnings.extend(times.warnings)
    if isinstance(video, VideoFile):
        count_warning = check_count(stamps.size, video.frame_count, video.name)
        if count_warning:
            warnings.append(count_warning)
    repeats = recorder_repeats(noted.mask(stamps.size), times)
    if np.any(repeats):
        warnings.append(caveat(
            f"{int(np.count_nonzero(repeats))} frame(s) repeat the one before exactly, whole (inserted by the recorder); "
            "they were left out",
            "film at a rate, size or quality the recorder keeps up with, so that it inserts no copies",
        ))  # fmt: skip
    led = tracked.track_of(0, times.t, repeats)
    sphere = tracked.track_of(1, times.t, repeats)
    led_roi, sphere_roi, rule = calibration.led.roi, calibration.sphere.roi, calibration.led_rule
    if not calibration.decided:
        identity = _identity(led, sphere, times.fps)
        rule = identity.rule()
        if not identity.first_is_led:
            led, sphere, led_roi, sphere_roi = sphere, led, sphere_roi, led_roi
    diagnostics: dict[str, Any] = {
        "time_source": times.source,
        "dropped_frames": times.dropped,
        "repeated_frames": int(np.count_nonzero(repeats)),
        "variable_frame_rate": times.variable,
        "detection_rate": {"led": float(np.mean(led.valid)), "sphere": float(np.mean(sphere.valid))},
        "clipped_frames": {"led": int(np.count_nonzero(led.clipped)), "sphere": int(np.count_nonzero(sphere.clipped))},
    }
    tracks = Tracks(
        led,
        sphere,
        stamps,
        times,
        led_roi,
        sphere_roi,
        calibration.roi_source,
        rule,
        tuple(warnings),
        diagnostics,
        seconds,
        video.frame_size,
    )
    if tracks_csv is not None:
        tracks.write_csv(tracks_csv)
    check_track(led, "LED", warnings)
    check_track(sphere, "sphere", warnings)
    return dataclasses.replace(tracks, warnings=tuple(warnings))
