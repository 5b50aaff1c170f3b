"""The LED's blink code, and finding where a camera's frames fall on the board's clock from it.

The board plays a pseudo-random bit sequence on the LED (its protocol, rig/board/protocol.h, gives
the LFSR) and reports every change of the LED with its board time. A camera that films the LED sees
the code as a per-frame on/off sequence. `align_blink_code` finds the offset between the camera's
clock and the board's (board time = camera time + offset): first the one offset at which the
whole code matches (the code does not repeat, so there is one), then an interval of offsets from
every on/off transition, each of which the board places between two frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from analysis.board.intervals import consistent_intersection
from analysis.errors import AnalysisError

# RIG_BLINK_LFSR_TAPS of the board's protocol (rig/board/protocol.h); tests/rig/board checks that
# the two agree.
LFSR_TAPS = 0xB400

# The coarse search accepts an offset when this share of the frames agree with the code ...
MIN_AGREEMENT = 0.9
# ... and no offset farther than two bits from it comes within this share of it.
AMBIGUITY_MARGIN = 0.1
MIN_FRAMES = 16


def lfsr_bits(seed: int, count: int) -> NDArray[np.bool_]:
    """The first `count` bits of the blink code from `seed` (the bit shifted out at each step)."""
    if not 0 < seed < 1 << 16:
        raise ValueError(f"seed must be 1..65535, got {seed}")
    state = seed
    bits = np.empty(count, dtype=bool)
    for k in range(count):
        out = state & 1
        state >>= 1
        if out:
            state ^= LFSR_TAPS
        bits[k] = bool(out)
    return bits


@dataclass(frozen=True)
class BlinkSchedule:
    """A blink as asked of the board: bit k lights the LED at `level` (or leaves it off) from
    board time start + k * bit_s; the LED is off after the last bit."""

    start_board_time: float
    bit_s: float
    seed: int
    bits: int
    level: int

    def code(self) -> NDArray[np.bool_]:
        return lfsr_bits(self.seed, self.bits)

    def led_on(self, board_times: ArrayLike) -> NDArray[np.bool_]:
        """Whether the schedule has the LED on at each board time."""
        times = np.asarray(board_times, dtype=np.float64)
        index = np.floor((times - self.start_board_time) / self.bit_s).astype(np.int64)
        inside = (index >= 0) & (index < self.bits)
        on = np.zeros(times.shape, dtype=bool)
        on[inside] = self.code()[index[inside]]
        return on


@dataclass(frozen=True)
class BlinkAlignment:
    """board time = camera time + offset_s, with the offset known to lie in [low_s, high_s];
    agreement is the share of the frames within the blink that the board's record explains at
    offset_s."""

    offset_s: float
    low_s: float
    high_s: float
    agreement: float
    frames_used: int
    transitions_used: int
    transitions_seen: int


def _led_state(change_times: NDArray[np.float64], change_on: NDArray[np.bool_], times: NDArray[np.float64]) -> NDArray[np.bool_]:
    index = np.searchsorted(change_times, times, side="right") - 1
    state = np.zeros(times.shape, dtype=bool)
    state[index >= 0] = change_on[index[index >= 0]]
    return state


def _agreement(
    offsets: NDArray[np.float64],
    frame_times: NDArray[np.float64],
    led_on: NDArray[np.bool_],
    change_times: NDArray[np.float64],
    change_on: NDArray[np.bool_],
    min_frames: int,
) -> NDArray[np.float64]:
    """Share of the frames inside the board's record that agree with it, for each offset (0 where
    too few frames fall inside)."""
    scores = np.zeros(offsets.shape)
    for i, offset in enumerate(offsets):
        board_times = frame_times + offset
        inside = (board_times >= change_times[0]) & (board_times <= change_times[-1])
        if inside.sum() >= min_frames:
            predicted = _led_state(change_times, change_on, board_times[inside])
            scores[i] = np.mean(predicted == led_on[inside])
    return scores


def align_blink_code(
    frame_times: ArrayLike,
    led_on: ArrayLike,
    change_times: ArrayLike,
    change_levels: ArrayLike,
    *,
    exposure_s: float = 0.0,
) -> BlinkAlignment:
    """Aligns a camera's view of the LED to the board's record of it.

    frame_times: (N,) camera time of each frame (s), increasing; the instant it samples the LED,
        mid-exposure.
    led_on: (N,) whether the LED is lit in each frame.
    change_times, change_levels: (M,) the board's LED changes (board seconds, level 0..255), as in
        a recording's led.csv; the LED is off before the first.
    exposure_s: the camera's exposure; a transition within half of it of a frame may show either way.

    Returns the offset with board time = camera time + offset, and the interval it must lie in.
    Raises AnalysisError when the code is not found or matches at more than one offset.
    """
    frames = np.asarray(frame_times, dtype=np.float64)
    on = np.asarray(led_on, dtype=bool)
    times = np.asarray(change_times, dtype=np.float64)
    levels = np.asarray(change_levels)
    if frames.ndim != 1 or frames.shape != on.shape or frames.size < MIN_FRAMES:
        raise AnalysisError(f"need at least {MIN_FRAMES} camera frames with one on/off value each, got {frames.size}")
    if np.any(np.diff(frames) <= 0):
        raise AnalysisError("camera frame times must increase")
    if times.ndim != 1 or times.shape != levels.shape or times.size < 2:
        raise AnalysisError("need the board's LED changes (led.csv of a recording with a blink)")
    if exposure_s < 0:
        raise ValueError(f"exposure_s must be >= 0, got {exposure_s}")
    order = np.argsort(times, kind="stable")
    times, lit = times[order], levels[order] > 0

    frame_step = float(np.median(np.diff(frames)))
    shortest_bit = float(np.min(np.diff(times))) if times.size > 1 else frame_step
    step = 0.5 * min(frame_step, shortest_bit)
    span = (times[0], times[-1])
    offsets = np.arange(span[0] - frames[-1], span[1] - frames[0] + step, step)
    could_fit = min(frames.size, int((span[1] - span[0]) / frame_step))
    scores = _agreement(offsets, frames, on, times, lit, max(MIN_FRAMES, could_fit // 2))
    best = int(np.argmax(scores))
    if scores[best] < MIN_AGREEMENT:
        raise AnalysisError(
            f"the blink code was not found in the video: at best {scores[best]:.0%} of frames agree "
            "(is the LED in view, is the on/off threshold right, was the blink recorded?)"
        )
    far = np.abs(offsets - offsets[best]) > 2 * shortest_bit
    if np.any(far) and scores[far].max() > scores[best] - AMBIGUITY_MARGIN:
        raise AnalysisError("the blink code matches the video at two offsets: record a longer blink")
    coarse = float(offsets[best])

    # Each transition between frames k-1 and k brackets a board change j of the same direction:
    # frames[k-1] + offset < times[j] <= frames[k] + offset (widened by half the exposure).
    half = 0.5 * exposure_s
    lows: list[float] = []
    highs: list[float] = []
    seen = 0
    for k in np.flatnonzero(on[1:] != on[:-1]) + 1:
        seen += 1
        candidates = np.flatnonzero((lit == on[k]) & (np.abs(times - (frames[k] + coarse)) <= frame_step + shortest_bit))
        if candidates.size == 0:
            continue
        j = candidates[np.argmin(np.abs(times[candidates] - (frames[k] + coarse)))]
        lows.append(times[j] - frames[k] - half)
        highs.append(times[j] - frames[k - 1] + half)
    if not lows:
        raise AnalysisError("the video shows no LED transitions to time the blink code by")
    low, high, members = consistent_intersection(lows, highs)
    board_times = frames + 0.5 * (low + high)
    inside = (board_times >= span[0]) & (board_times <= span[1])
    agreement = np.mean(_led_state(times, lit, board_times[inside]) == on[inside])
    return BlinkAlignment(
        offset_s=0.5 * (low + high),
        low_s=low,
        high_s=high,
        agreement=float(agreement),
        frames_used=int(inside.sum()),
        transitions_used=len(members),
        transitions_seen=seen,
    )
