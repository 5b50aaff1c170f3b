"""The rig's board, simulated beside the pendulum: it plays the LED blink code and counts the
pendulum's encoder on its own clock, and the run records what it reports as a real board recording.

The board's clock runs `board_offset_s` ahead of the simulation's: board time = simulation time +
offset, counted in ticks of RIG_TICK_HZ (rig/board/protocol.h) like the real board's.

The LED is on at `blink_level` throughout the run, except during the blink: from `blink_start_s`
(simulation time) bit k of the code (analysis.board.blink_code.lfsr_bits) holds it at blink_level or
off for [start + k bit_s, start + (k + 1) bit_s); after the last bit it is on again.

The encoder reads count = floor(theta * counts_per_rev / (2 pi) + 0.5), as the emulated board's
encoder does (firmware/sim/rig_board_sim.c), so the count steps from c - step to c where the angle
crosses (c - step / 2) * 2 pi / counts_per_rev. The run is cut into the intervals of a dense grid,
split further at the swing's turning points (found by bisection), so the angle is monotonic in
each: every crossing in one is found, none is missed, and each is solved for by Newton's method
kept inside its interval, to far better than a microsecond.

Written into the board folder as the run goes, through rig.board.recorder's writer in the format
of analysis.board.recording:
led.csv (the switch-on at the start of the run, every change during the blink with its bit, the
switch back on after it), encoder.csv (every edge, `edges` = 1 as a board reporting every edge
sends), the other files of a recording with their headers only, and recording.json at the end.
rig_time_s is the simulation time of each event.
"""

from __future__ import annotations

import math
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from analysis.board.recording import METADATA, TABLES
from rig.board.events import BoardIdentity, EncoderEdge, LedChange
from rig.board.protocol import protocol
from rig.board.recorder import BoardRecorder
from rig.clock import Clock
from rig.session.run_files import BOARD_FOLDER
from rig.sim.pendulum import Pendulum
from rig.sim.board_config import SimulatedBoardConfig

__all__ = ["BOARD_FOLDER", "SimulatedBoard", "SimulatedBoardConfig", "encoder_count", "remove_recording"]
# Simulation seconds of encoder edges worked out at a time, and the grid they are bracketed on.
_ENCODER_BLOCK_S = 0.25
_GRID_STEP_S = 1e-3
_GRID_PER_PERIOD = 200
_BISECTIONS = 40
_MAX_ITERATIONS = 80
_TIME_TOLERANCE_S = 1e-12


def encoder_count(angle: ArrayLike, counts_per_rev: int) -> NDArray[np.int64]:
    """The encoder's count at pendulum angles (rad): floor(angle * counts_per_rev / (2 pi) + 0.5)."""
    return np.floor(np.asarray(angle, dtype=np.float64) * counts_per_rev / (2.0 * np.pi) + 0.5).astype(np.int64)


class _EncoderEdges:
    """The encoder's edges, worked out block by block in time order (see the module docstring)."""

    def __init__(self, pendulum: Pendulum, counts_per_rev: int, t_begin: float) -> None:
        self._pendulum = pendulum
        self._scale = counts_per_rev / (2.0 * np.pi)
        self._grid_step = min(_GRID_STEP_S, pendulum.period_s / _GRID_PER_PERIOD)
        self.t_done = t_begin
        self._position = float(self._position_at(np.array([t_begin]))[0])

    def _position_at(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        """theta * counts_per_rev / (2 pi) + 0.5: the count is its floor."""
        return self._pendulum.angle(t) * self._scale + 0.5

    def _knots(self, t1: float) -> NDArray[np.float64]:
        """Times from t_done to t1 between which the angle is monotonic."""
        steps = max(1, math.ceil((t1 - self.t_done) / self._grid_step))
        grid = np.linspace(self.t_done, t1, steps + 1)
        if self.t_done < self._pendulum.t_release < t1:
            grid = np.sort(np.append(grid, self._pendulum.t_release))
        velocity = self._pendulum.angular_velocity(grid)
        turning = np.flatnonzero(velocity[:-1] * velocity[1:] < 0.0)
        if turning.size == 0:
            return grid
        low, high = grid[turning], grid[turning + 1]
        rising = velocity[turning] < 0.0
        for _ in range(_BISECTIONS):
            middle = 0.5 * (low + high)
            below = self._pendulum.angular_velocity(middle) < 0.0
            low, high = np.where(below == rising, middle, low), np.where(below == rising, high, middle)
        return np.sort(np.concatenate([grid, 0.5 * (low + high)]))

    def advance(self, t1: float) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
        """Times, counts after, and steps (+-1) of the edges in (t_done, t1], in time order."""
        knots = self._knots(t1)
        position = self._position_at(knots)
        position[0] = self._position
        count = np.floor(position).astype(np.int64)
        self.t_done = float(knots[-1])
        self._position = float(position[-1])
        changed = np.flatnonzero(count[1:] != count[:-1])
        if changed.size == 0:
            return np.empty(0), np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
        # rising, the count becomes m where the position reaches m; falling, it becomes m - 1 there
        interval, target, step = [], [], []
        for i in changed:
            rising = count[i + 1] > count[i]
            levels = np.arange(count[i] + 1, count[i + 1] + 1) if rising else np.arange(count[i], count[i + 1], -1)
            interval.append(np.full(levels.size, i))
            target.append(levels)
            step.append(np.full(levels.size, 1 if rising else -1))
        where, targets, steps = np.concatenate(interval), np.concatenate(target), np.concatenate(step)
        times = self._crossings(knots[where], knots[where + 1], position[where], position[where + 1], targets.astype(np.float64), steps)
        return times, targets - (steps < 0), steps

    def _crossings(
        self,
        low: NDArray[np.float64],
        high: NDArray[np.float64],
        position_low: NDArray[np.float64],
        position_high: NDArray[np.float64],
        target: NDArray[np.float64],
        step: NDArray[np.int64],
    ) -> NDArray[np.float64]:
        """The times in [low, high] where the position, monotonic there, passes target (upwards
        for step +1): Newton's method from the linear interpolate, bisecting whenever a step would
        leave the interval that still brackets the crossing."""
        t = low + (target - position_low) / (position_high - position_low) * (high - low)
        for _ in range(_MAX_ITERATIONS):
            miss = self._position_at(t) - target
            reached = miss * step >= 0.0
            low, high = np.where(reached, low, t), np.where(reached, t, high)
            slope = self._pendulum.angular_velocity(t) * self._scale
            with np.errstate(divide="ignore", invalid="ignore"):
                newton = t - miss / slope
            following = np.where((newton > low) & (newton < high), newton, 0.5 * (low + high))
            done = np.max(np.abs(following - t)) < _TIME_TOLERANCE_S
            t = following
            if done:
                break
        return t


class SimulatedBoard:
    """The simulated board as an instrument beside a run (`rig.devices.protocols.Instrument`): once
    connected, it records into `out_dir` what the board reports up to the rig clock's present, at
    every poll, over [t_begin, t_end]. `finish` completes the recording with recording.json, as
    `rig board record` does at the end of a recording; `close` records up to the present and
    closes the files, so an interrupted run keeps a readable recording (without recording.json)."""

    def __init__(self, config: SimulatedBoardConfig, pendulum: Pendulum, t_begin: float, t_end: float, out_dir: Path) -> None:
        self.config = config
        self.t_begin = t_begin
        self.t_end = t_end
        self.out_dir = Path(out_dir)
        self.release_s = pendulum.config.release_s
        self._tick_hz = protocol()["RIG_TICK_HZ"]
        self._led = config.led_changes(t_begin)
        self._encoder = _EncoderEdges(pendulum, config.counts_per_rev, t_begin)
        self._pending: tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]] | None = None
        self._clock: Clock | None = None
        self.recorder: BoardRecorder | None = None

    def connect(self, clock: Clock) -> None:
        self.recorder = BoardRecorder(self.out_dir)
        self._clock = clock

    def poll(self) -> None:
        """Record every event up to the present."""
        if self._clock is None:
            raise RuntimeError("the simulated board is not connected")
        self._record_until(self._clock.now())

    def finish(self) -> None:
        """Record up to the present and write recording.json."""
        self.poll()
        self._write_metadata()

    def close(self) -> None:
        """Record up to the present and close the files."""
        if self._clock is None:
            return
        try:
            self.poll()
        finally:
            self.recorder.close()
            self._clock = None

    def _ticked(self, t: float) -> tuple[int, float]:
        """The board tick and board time of simulation time t."""
        tick = round((t + self.config.board_offset_s) * self._tick_hz)
        return tick, tick / self._tick_hz

    def _record_until(self, t: float) -> None:
        """Write every LED change and encoder edge at simulation times up to t (at most t_end)."""
        t = min(t, self.t_end)
        while self._led and self._led[0][0] <= t:
            time, level, bit = self._led.pop(0)
            self.recorder.on_event(LedChange(*self._ticked(time), time, level, bit))
        while True:
            if self._pending is None:
                if self._encoder.t_done >= t:
                    break
                self._pending = self._encoder.advance(min(self._encoder.t_done + _ENCODER_BLOCK_S, self.t_end))
            times, counts, steps = self._pending
            due = int(np.searchsorted(times, t, side="right"))
            for time, count, step in zip(times[:due].tolist(), counts[:due].tolist(), steps[:due].tolist()):
                self.recorder.on_event(EncoderEdge(*self._ticked(time), time, count, step, 1))
            if due < times.size:
                self._pending = (times[due:], counts[due:], steps[due:])
                break
            self._pending = None
        self.recorder.on_batch_end()

    def _write_metadata(self) -> None:
        spec = protocol()
        identity = BoardIdentity(
            name="simulated",
            protocol=spec["RIG_PROTOCOL_VERSION"],
            firmware="simulation",
            tick_hz=self._tick_hz,
            cpu_hz=0,
        )
        self.recorder.write_metadata(
            {
                "identity": asdict(identity),
                "simulated": True,
                "rig_time": "the simulation's clock: board time = rig time + board_offset_s",
                "options": {"duration_s": self.t_end - self.t_begin, "encoder_rate_hz": 0.0},
                "board": asdict(self.config),
                "blink": asdict(self.config.schedule()),
                "release_s": self.release_s,
                "events": self.recorder.counts,
            }
        )

    def truth(self) -> dict[str, Any]:
        """What truth.json says about the board: its clock offset, the pendulum's release (None: it
        swung throughout) and the blink on the board's clock."""
        return {"offset_s": self.config.board_offset_s, "release_s": self.release_s, "blink": asdict(self.config.schedule())}


def remove_recording(folder: Path) -> None:
    """Remove a board recording's files from `folder` (nothing else), and the folder if that empties it."""
    for name in [table.name for table in TABLES] + [METADATA]:
        (folder / name).unlink(missing_ok=True)
    if folder.is_dir() and not any(folder.iterdir()):
        folder.rmdir()
