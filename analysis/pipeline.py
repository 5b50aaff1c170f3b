"""The whole analysis in one call: ``analyse`` tracks a video (``analysis.tracks.track``) and
measures the latency in its tracks (``analysis.estimation.estimate``)."""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

from analysis.estimation import estimate
from analysis.estimators.contract import Estimator
from analysis.estimators.registry import estimators_for
from analysis.options import AnalysisOptions
from analysis.result import LatencyResult
from analysis.blobs import Track
from analysis.tracks import track


def analyse(
    source: str | Path | np.ndarray,
    options: AnalysisOptions = AnalysisOptions(),
    *,
    progress: Callable[[int, int], object] | None = None,
    tracks_csv: str | Path | None = None,
    reference_departures: Callable[[Track], Mapping[str, float]] | None = None,
) -> LatencyResult:
    """Measure the latency between the LED and the rendered sphere in a video.

    ``source`` is a video file, a folder of numbered images, or an array of frames, (N, H, W) grey
    or (N, H, W, 3) BGR. ``options`` (``analysis.options.AnalysisOptions``) say how: the frame rate
    (required for arrays and image folders), the regions or the LED's side (else the two largest
    moving bright regions are used, the LED the one the physical evidence names, and an
    AnalysisError asks for the regions when it does not decide), the estimator, the latencies
    considered, the bayes sampler's seed, what the user knows of the display's refresh rate and
    the camera's exposure (else the video is searched for both, to work out how the camera's
    sampling of the display biases the latency, ``analysis.sampling``), and of the camera's
    rolling-shutter readout (each blob's samples are then dated by their rows; else the interval
    allows for any readout up to the frame interval, ``analysis.readout``).
    ``progress(done, total)`` is called as frames are tracked (for clips of
    ``analysis.tracks.PROGRESS_MIN_SECONDS`` or more); ``tracks_csv`` receives the tracks as they
    are measured. ``reference_departures(led_track)`` names times (s, on the video's clock) at which
    other instruments saw the pendulum depart from rest, in the sense of ``analysis.onset`` (e.g. a
    rig board's encoder, its clock aligned by the LED's blink code, which it reads from the LED
    track); with the sphere's departure each gives a lag that fixes the whole number of periods.
    """
    # The options were checked when they were made, before the video is read: a typo costs no tracking pass.
    preparing = _prepare_in_background(estimators_for(options.method))
    try:
        tracks = track(source, options, progress=progress, tracks_csv=tracks_csv)
    except BaseException as error:
        if not isinstance(error, KeyboardInterrupt):  # an interrupt stops at once; the imports end on their own
            preparing.join()
        raise
    preparing.join()
    return estimate(tracks, options, reference_departures=reference_departures)


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
