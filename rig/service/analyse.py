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
from analysis import AnalysisOptions, LatencyResult
from analysis.board.reference import BoardReference


@dataclass(frozen=True)
class AnalysisRequest:
    """A video to analyse, how (`analysis.AnalysisOptions`), where its tracks go as they are
    measured (`tracks_csv`), and the board recording made beside it (`board`, a folder)."""

    video: Path
    options: AnalysisOptions = AnalysisOptions()
    board: Path | None = None
    tracks_csv: Path | None = None


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
    departures = board.departures if board is not None else None
    result = analysis.analyse(
        request.video, request.options, progress=progress, tracks_csv=request.tracks_csv, reference_departures=departures
    )
    return Measurement(result, board)
