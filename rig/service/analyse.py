"""Measure the latency in a video: the analyser (`analysis`), with the rig board's recording when
there is one.

With a `rig board record --blink` folder, the LED's blink code puts the video on the board's
clock and the encoder's start of swing (`analysis.board.reference`) fixes the whole number of
swing periods in the latency.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import analysis
from analysis import LatencyResult
from analysis.board.reference import BoardReference
from analysis.cycles import DEFAULT_LATENCY_RANGE_S
from analysis.estimators.registry import DEFAULT_METHOD

DEFAULT_LATENCY_RANGE_MS = (DEFAULT_LATENCY_RANGE_S[0] * 1e3, DEFAULT_LATENCY_RANGE_S[1] * 1e3)


@dataclass(frozen=True)
class AnalysisRequest:
    """What to analyse and how (see `analysis.analyse`); `board` is a board recording folder;
    `display_hz` and `exposure_ms` are the display's refresh rate and the camera's exposure, where
    the lab knows them (else the video is searched for both); `readout_ms` the camera's rolling-shutter
    readout, 0 for a global shutter (else bounded by the frame rate)."""

    video: Path
    fps: float | None = None
    led_roi: tuple[int, int, int, int] | None = None
    sphere_roi: tuple[int, int, int, int] | None = None
    led_side: str | None = None
    method: str = DEFAULT_METHOD
    latency_range_ms: tuple[float, float] = DEFAULT_LATENCY_RANGE_MS
    seed: int = 0
    tracks_csv: Path | None = None
    board: Path | None = None
    display_hz: float | None = None
    exposure_ms: float | None = None
    readout_ms: float | None = None


@dataclass(frozen=True)
class Measurement:
    """The analyser's result and, where a board recording was used, what it told."""

    result: LatencyResult
    board: BoardReference | None

    def to_dict(self) -> dict[str, Any]:
        return self.result.to_dict() | ({"board": self.board.to_dict()} if self.board is not None else {})


def analyse(request: AnalysisRequest, progress: Callable[[int, int], object] | None = None) -> Measurement:
    """Analyse the request's video; `progress(done, total)` as frames are tracked."""
    board = BoardReference.load(request.board) if request.board is not None else None
    result = analysis.analyse(
        request.video,
        fps=request.fps,
        led_roi=request.led_roi,
        sphere_roi=request.sphere_roi,
        led_side=request.led_side,
        method=request.method,
        latency_range_ms=request.latency_range_ms,
        progress=progress,
        tracks_csv=request.tracks_csv,
        seed=request.seed,
        reference_departures=board.departures if board is not None else None,
        refresh_hz=request.display_hz,
        exposure_ms=request.exposure_ms,
        readout_ms=request.readout_ms,
    )
    return Measurement(result, board)
