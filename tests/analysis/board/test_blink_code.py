"""The LED blink code, and aligning a camera's view of it to the board's record."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.board.blink_code import BlinkSchedule, align_blink_code, lfsr_bits
from analysis.errors import AnalysisError

SCHEDULE = BlinkSchedule(start_board_time=500.0, bit_s=0.05, seed=0xACE1, bits=64, level=255)


def board_changes(schedule: BlinkSchedule, late_s: float = 20e-6) -> tuple[np.ndarray, np.ndarray]:
    """The LED changes the board reports for a schedule (each a little after its bit starts)."""
    levels = np.append(np.where(schedule.code(), schedule.level, 0), 0)
    previous = np.concatenate([[0], levels[:-1]])
    flips = np.flatnonzero(levels != previous)
    return schedule.start_board_time + flips * schedule.bit_s + late_s, levels[flips]


def camera_view(
    schedule: BlinkSchedule, offset: float, *, fps: float = 60.0, start: float = -1.0, seconds: float = 5.0, jitter: float = 0.0, seed: int = 0
) -> tuple[np.ndarray, np.ndarray]:
    """Camera frame times (camera clock, board = camera + offset) and what each shows."""
    rng = np.random.default_rng(seed)
    frames = schedule.start_board_time - offset + start + np.arange(0.0, seconds, 1 / fps)
    frames += rng.uniform(-jitter, jitter, frames.size)
    return frames, schedule.led_on(frames + offset)


def test_lfsr_has_its_maximal_period() -> None:
    bits = lfsr_bits(1, 65535 + 16)
    assert np.array_equal(bits[:16], bits[65535:])
    assert not np.array_equal(bits[:16], bits[1000:1016])
    assert 0.45 < bits[:65535].mean() < 0.55
    with pytest.raises(ValueError):
        lfsr_bits(0, 8)


def test_schedule_says_when_the_led_is_on() -> None:
    code = SCHEDULE.code()
    times = SCHEDULE.start_board_time + (np.arange(SCHEDULE.bits) + 0.5) * SCHEDULE.bit_s
    assert np.array_equal(SCHEDULE.led_on(times), code)
    assert not SCHEDULE.led_on([SCHEDULE.start_board_time - 1e-3, SCHEDULE.start_board_time + SCHEDULE.bits * SCHEDULE.bit_s]).any()


@pytest.mark.parametrize(("offset", "fps", "jitter"), [(1234.5678, 59.94, 0.0), (-20.0001, 239.76, 0.5e-3), (0.3, 29.97, 1e-3)])
def test_camera_is_aligned_to_the_board(offset: float, fps: float, jitter: float) -> None:
    changes = board_changes(SCHEDULE)
    frames, lit = camera_view(SCHEDULE, offset, fps=fps, jitter=jitter, seed=1)
    alignment = align_blink_code(frames, lit, *changes, exposure_s=0.0)
    truth = offset + 20e-6
    assert alignment.low_s - 1e-9 <= truth <= alignment.high_s + 1e-9
    # Each transition brackets the offset within a frame interval; transitions falling at other
    # phases of the frames narrow it further.
    assert alignment.high_s - alignment.low_s <= 1 / fps + 2 * jitter
    assert alignment.agreement == 1.0
    assert alignment.transitions_used == alignment.transitions_seen


def test_a_misread_frame_is_outvoted() -> None:
    changes = board_changes(SCHEDULE)
    frames, lit = camera_view(SCHEDULE, 7.25, fps=119.88, seed=2)
    steady = [k for k in range(2, lit.size - 2) if np.all(lit[k - 2 : k + 3] == lit[k]) and lit[k]]
    lit = lit.copy()
    lit[steady[len(steady) // 2]] = False  # a frame in the middle of a lit bit read dark
    alignment = align_blink_code(frames, lit, *changes)
    assert alignment.low_s - 1e-9 <= 7.25 + 20e-6 <= alignment.high_s + 1e-9
    assert alignment.transitions_used <= alignment.transitions_seen - 2
    assert 0.99 < alignment.agreement < 1.0


def test_exposure_widens_the_interval() -> None:
    changes = board_changes(SCHEDULE)
    frames, lit = camera_view(SCHEDULE, 3.0, fps=59.94, seed=3)
    sharp = align_blink_code(frames, lit, *changes)
    blurred = align_blink_code(frames, lit, *changes, exposure_s=0.008)
    assert blurred.high_s - blurred.low_s == pytest.approx(sharp.high_s - sharp.low_s + 0.008)


def test_video_without_the_code_is_refused() -> None:
    changes = board_changes(SCHEDULE)
    frames = np.arange(0.0, 5.0, 1 / 60)
    rng = np.random.default_rng(4)
    with pytest.raises(AnalysisError, match="not found"):
        align_blink_code(frames, rng.random(frames.size) < 0.5, *changes)
    with pytest.raises(AnalysisError, match="at least 16 camera frames"):
        align_blink_code(frames[:5], np.zeros(5, dtype=bool), *changes)


def test_a_code_too_short_to_place_is_refused() -> None:
    short = BlinkSchedule(start_board_time=10.0, bit_s=0.05, seed=0xACE1, bits=3, level=255)
    frames, lit = camera_view(short, 0.0, start=-2.0, seconds=4.0)
    with pytest.raises(AnalysisError, match="two offsets|not found"):
        align_blink_code(frames, lit, *board_changes(short))
