"""A board recording as the camera path's reference: blink alignment, then the encoder's start of swing."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from analysis.board.blink_code import BlinkSchedule
from analysis.board.reference import EVENT_NAME, BoardReference, lit_frames
from analysis.errors import AnalysisError
from analysis.onset import departure_time
from analysis.blobs import Track
from rig.board.events import EncoderEdge, LedChange
from rig.board.recorder import BoardRecorder

FPS = 120.0
OFFSET_S = 250.0
RELEASE_S = 4.0
PERIOD_S = 1.3
AMPLITUDE_COUNTS = 140.0
SCHEDULE = BlinkSchedule(start_board_time=OFFSET_S + 0.5, bit_s=0.05, seed=0xACE1, bits=48, level=255)


def encoder_counts(video_t: np.ndarray, release_s: float = RELEASE_S) -> np.ndarray:
    since = np.maximum(video_t - release_s, 0.0)
    return AMPLITUDE_COUNTS * np.exp(-0.05 * since) * np.cos(2 * math.pi / PERIOD_S * since)


def write_recording(folder: Path, release_s: float = RELEASE_S) -> Path:
    """led.csv (the LED lit, the blink, lit again) and encoder.csv (edges of encoder_counts), as a board writes them."""
    recorder = BoardRecorder(folder)
    levels = np.append(np.where(SCHEDULE.code(), 255, 0), 255)
    times = SCHEDULE.start_board_time + SCHEDULE.bit_s * np.arange(levels.size)
    previous = 255
    recorder.on_event(LedChange(0, OFFSET_S - 0.5, 0.0, 255, None))
    for bit, (time, level) in enumerate(zip(times, levels)):
        if level != previous:
            recorder.on_event(LedChange(0, float(time), 0.0, int(level), bit if bit < SCHEDULE.bits else None))
            previous = level
    dense = np.arange(0.0, 12.0, 2e-5)
    counts = np.floor(encoder_counts(dense, release_s) + 0.5)
    for k, edge in enumerate(np.flatnonzero(np.diff(counts)) + 1):
        step = int(counts[edge] - counts[edge - 1])
        recorder.on_event(EncoderEdge(0, float(dense[edge] + OFFSET_S), 0.0, int(counts[edge]), step, k + 1))
    recorder.close()
    return folder


def led_track(seconds: float = 12.0) -> Track:
    """The LED as the analyser tracks it: its peak follows the blink (partly lit frames in between)."""
    t = np.arange(0.0, seconds, 1 / FPS)
    lit = np.array([SCHEDULE.led_on(start + OFFSET_S + np.linspace(0, 1 / FPS, 9)).mean() for start in t])
    lit[(t + OFFSET_S < SCHEDULE.start_board_time) | (t + OFFSET_S >= SCHEDULE.start_board_time + SCHEDULE.bits * SCHEDULE.bit_s)] = 1.0
    peak = 3.0 + 200.0 * lit
    valid = lit > 0.3
    x = np.where(valid, 50.0 + encoder_counts(t) / 4, np.nan)
    return Track(t, x, np.where(valid, 20.0, np.nan), valid, peak, np.zeros(t.size, dtype=bool))


def test_the_blink_puts_the_encoder_release_on_the_video_clock(tmp_path: Path) -> None:
    board = BoardReference.load(write_recording(tmp_path / "rec"))
    departures = board.departures(led_track())
    assert board.alignment is not None
    assert board.alignment.low_s - 1e-6 <= OFFSET_S <= board.alignment.high_s + 1e-6
    dense = np.arange(0.0, 12.0, 1e-3)
    expected = departure_time(dense, encoder_counts(dense), np.zeros_like(dense))
    assert departures[EVENT_NAME] == pytest.approx(expected, abs=2e-3)
    assert board.to_dict()["encoder_departure_board_s"] == pytest.approx(expected + OFFSET_S, abs=2e-3)


def test_an_encoder_already_swinging_fixes_nothing(tmp_path: Path) -> None:
    board = BoardReference.load(write_recording(tmp_path / "rec", release_s=-3.0))
    assert board.departures(led_track()) == {}
    assert board.alignment is not None and board.to_dict()["encoder_departure_board_s"] is None


def test_a_video_that_misses_the_blink_is_refused(tmp_path: Path) -> None:
    board = BoardReference.load(write_recording(tmp_path / "rec"))
    late = led_track()
    start = np.searchsorted(late.t, 4.5)
    cut = Track(*(column[start:] for column in (late.t, late.x, late.y, late.valid, late.peak, late.clipped)))
    with pytest.raises(AnalysisError, match="blink code was not found"):
        board.departures(cut)


def test_half_lit_frames_read_as_the_nearer_level() -> None:
    track = led_track(6.0)
    lit = lit_frames(track)
    assert np.array_equal(lit, track.peak > 103.0)


def test_a_recording_without_a_blink_is_refused(tmp_path: Path) -> None:
    BoardRecorder(tmp_path / "rec").close()
    with pytest.raises(AnalysisError, match="no blink"):
        BoardReference.load(tmp_path / "rec")
