"""The whole analysis in one call: ``analyse`` tracks a video (``analysis.tracks.track``) and
measures the latency in its tracks (``analysis.estimation.estimate``)."""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from analysis.cycles import DEFAULT_LATENCY_RANGE_S
from analysis.estimation import check_sampling_options, estimate, latency_range_s
from analysis.estimators.contract import Estimator
from analysis.estimators.registry import DEFAULT_METHOD, estimators_for
from analysis.result import LatencyResult
from analysis.tracking import Track
from analysis.tracks import track


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
    refresh_hz: float | None = None,
    exposure_ms: float | None = None,
    readout_ms: float | None = None,
) -> LatencyResult:
    """Measure the latency between the LED and the rendered sphere in a video.

    ``source`` is a video file, a folder of numbered images, or an array of frames, (N, H, W) grey
    or (N, H, W, 3) BGR; ``fps`` overrides the file's frame rate and is required for arrays and
    image folders. ROIs are [x, y, width, height] in pixels: give both or neither; without them the
    two largest moving bright regions are used, the LED being the one on ``led_side`` ("left" or
    "right") if given, else the one the physical evidence names (``analysis.identity``; an
    AnalysisError asks for the ROIs when it does not decide). ``method`` is a registered estimator's name (fft, xcorr,
    sinefit, bayes, see ``analysis.estimators.registry``) or all (every one, sinefit reported
    first). Latencies are looked for in ``latency_range_ms``.
    ``progress(done, total)`` is called as frames are tracked (for clips of
    ``analysis.tracks.PROGRESS_MIN_SECONDS`` or more); ``tracks_csv`` receives the tracks as they
    are measured. ``seed`` seeds the bayes sampler. ``reference_departures(led_track)``
    names times (s, on the video's clock) at which other instruments saw the pendulum depart from
    rest, in the sense of ``analysis.onset`` (e.g. a rig board's encoder, its clock aligned by the
    LED's blink code, which it reads from the LED track); with the sphere's departure each gives a
    lag that fixes the whole number of periods. ``refresh_hz`` (the display's refresh rate) and
    ``exposure_ms`` (the camera's exposure) are what the user knows of them; without them the video
    is searched for both, to work out how the camera's sampling of the display biases the latency
    (``analysis.sampling``). ``readout_ms`` is the time the camera's rolling shutter takes from the
    frame's top row to its bottom one (0 for a global shutter): each blob's samples are then dated
    by their rows; without it the interval allows for any readout up to the frame interval
    (``analysis.shutter``).
    """
    # The options are checked before the video is read: a typo should not cost a tracking pass.
    estimators = estimators_for(method)
    latency_range_s(latency_range_ms)
    check_sampling_options(refresh_hz, exposure_ms, readout_ms)
    preparing = _prepare_in_background(estimators)
    try:
        tracks = track(
            source, fps=fps, led_roi=led_roi, sphere_roi=sphere_roi, led_side=led_side, progress=progress, tracks_csv=tracks_csv
        )
    except BaseException as error:
        if not isinstance(error, KeyboardInterrupt):  # an interrupt stops at once; the imports end on their own
            preparing.join()
        raise
    preparing.join()
    return estimate(
        tracks,
        method,
        latency_range_ms=latency_range_ms,
        seed=seed,
        reference_departures=reference_departures,
        refresh_hz=refresh_hz,
        exposure_ms=exposure_ms,
        readout_ms=readout_ms,
    )


def _prepare_in_background(estimators: Sequence[Estimator]) -> threading.Thread:
    """Each estimator's ``prepare`` (its imports: JAX alone takes about a second) on a thread, so
    that it overlaps the tracking, whose decoding waits on OpenCV with the GIL released."""

    def prepare() -> None:
        for estimator in estimators:
            try:
                getattr(estimator, "prepare", lambda: None)()
            except Exception:  # noqa: BLE001 - estimate() meets the same failure and reports it
                return

    thread = threading.Thread(target=prepare, name="analysis-prepare", daemon=True)
    thread.start()
    return thread
