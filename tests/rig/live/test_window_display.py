"""The window display against a fake window on a virtual clock: images reach the refresh they were
aimed at (never one already accounted for as shown), swaps that overrun are late (the display
repeated its image), every swap is logged, and a closed window ends the run. Measured refreshes
come from the swaps' own times. A frame clock that stalls on purpose makes the run's health
invalid, the stall named."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Iterator

import numpy as np
import pytest

from rig.clock import VirtualClock
from rig.devices.protocols import NO_IMAGE
from rig.devices.window import SwapRecord, WindowDisplay, WindowSettings
from predictors import SAMPLE_COLUMNS, PoseSample, sample_row
from rig.devices.window import SWAP_COLUMNS
from rig.errors import RigError
from rig.live.health import INVALID, run_health
from rig.live.selftest.frame_clock import START_DELAY_S, FixedRateFrameClock
from rig.writers import CsvRecord

PERIOD = 1.0 / 60.0


class FakeWindow:
    """A window whose swap takes `swap_s` on the clock; with `vsync`, it returns at the next blank."""

    def __init__(self, clock: VirtualClock, swap_s: float = 1e-3, vsync: bool = False) -> None:
        self.clock = clock
        self.swap_s = swap_s
        self.vsync = vsync
        self.width, self.height = 64, 48
        self.drawn: list[int] = []
        self.closed = False
        self.ask_close = False

        class Context:
            extensions: set[str] = set()

        self.ctx = Context()

    @contextlib.contextmanager
    def current(self) -> Iterator[None]:
        yield

    def native_glx(self) -> None:
        return None

    def proc_address(self, name: str) -> int:
        return 0

    def extension_supported(self, name: str) -> bool:
        return False

    def draw(self, image: np.ndarray) -> None:
        self.drawn.append(int(image[0, 0, 0]))

    def swap(self) -> None:
        t = self.clock.now() + self.swap_s
        if self.vsync:
            t = (np.floor(t / PERIOD) + 1) * PERIOD
        self.clock.wait_until(t)

    def closing(self) -> bool:
        return self.ask_close

    def close(self) -> None:
        self.closed = True


def _display(clock: VirtualClock, window: FakeWindow, swaps: list[SwapRecord], paced: bool = True) -> WindowDisplay:
    display = WindowDisplay(
        WindowSettings(size=(64, 48)), frame_clock=FixedRateFrameClock(60.0) if paced else None, swap_log=swaps.append,
        open_window=lambda settings: window,
    )  # fmt: skip
    display.connect(clock)
    return display


def _image(value: int) -> np.ndarray:
    return np.full((48, 64, 3), value, dtype=np.uint8)


def test_images_appear_at_the_refreshes_they_are_ready_for_and_stay() -> None:
    clock, swaps = VirtualClock(), []
    display = _display(clock, FakeWindow(clock), swaps)
    first = display.present(_image(1), clock.now(), 1)
    second = display.present(_image(2), clock.now(), 2)
    assert second == first + 1
    shown = [display.shown(k) for k in range(second + 2)]
    assert shown[:first] == [NO_IMAGE] * first and shown[first:] == [1, 2, 2]
    assert [s.refresh for s in swaps] == [first, second] and all(s.refresh == s.aimed_refresh for s in swaps)
    assert display.vblank_time(second) == swaps[1].t_swap
    assert display.photon_time(second, 0.5) == pytest.approx(swaps[1].t_swap + 0.5 * PERIOD)


@pytest.mark.parametrize("paced", [True, False], ids=["frame-clock", "swap-return"])
def test_an_image_ready_early_waits_for_the_first_refresh_not_yet_accounted_for(paced: bool) -> None:
    """A compositor that planned for a slow composition (the first on a machine compiles its shaders)
    has run the session's refreshes ahead of the clock; the next image, done sooner, must appear at
    the first refresh the session has not yet counted as shown. Swapped at once it appeared at a
    refresh already logged as dark, and the compositor, aiming past it, froze."""
    clock, swaps = VirtualClock(10.0), []
    window = FakeWindow(clock, swap_s=2e-4, vsync=not paced)
    display = _display(clock, window, swaps, paced=paced)
    ahead = display.refresh_after(clock.now()) + 5
    assert [display.shown(k) for k in range(ahead)] == [NO_IMAGE] * ahead
    assert display.present(_image(1), clock.now(), 1) == ahead
    assert display.shown(ahead) == 1
    assert swaps[0].refresh == swaps[0].aimed_refresh == ahead
    assert display.vblank_time(ahead - 1) < swaps[0].t_swap <= display.vblank_time(ahead) + 1e-3


def test_a_swap_that_overruns_its_refresh_is_late_and_logged_so() -> None:
    clock, swaps = VirtualClock(), []
    window = FakeWindow(clock, swap_s=1.5 * PERIOD)
    display = _display(clock, window, swaps)
    display.present(_image(1), clock.now(), 1)
    assert swaps[0].refresh == swaps[0].aimed_refresh + 1
    assert swaps[0].late == 1
    assert display.report()["late_swaps"] == 1


def test_a_display_paced_by_its_swaps_is_measured_from_them() -> None:
    clock, swaps = VirtualClock(10.0), []
    window = FakeWindow(clock, swap_s=2e-4, vsync=True)
    display = _display(clock, window, swaps, paced=False)
    assert display.refresh_hz == pytest.approx(60.0, rel=1e-3)
    assert display.timing_source == "swap-return"
    k = display.present(_image(1), clock.now(), 1)
    assert abs(swaps[0].t_swap - display.vblank_time(k)) < 1e-12
    assert display.refresh_after(display.vblank_time(k)) == k + 1


def test_an_unpaced_display_is_refused_with_one_clear_message() -> None:
    clock = VirtualClock()
    with pytest.raises(RigError, match="vsync is off"):
        _display(clock, FakeWindow(clock, swap_s=2e-4), [], paced=False)


def test_closing_the_window_ends_the_run() -> None:
    clock = VirtualClock()
    window = FakeWindow(clock)
    display = _display(clock, window, [])
    window.ask_close = True
    with pytest.raises(RigError, match="window was closed"):
        display.present(_image(1), clock.now(), 1)
    display.close()
    assert window.closed


class StallingFrameClock(FixedRateFrameClock):
    """Refreshes at 60 Hz, but none for `stall_s` before refresh `at` (a display or a rig that froze)."""

    def __init__(self, at: int, stall_s: float) -> None:
        super().__init__(60.0)
        self.at, self.stall_s = at, stall_s

    def vblank(self, k: int) -> float:
        return super().vblank(k) + (self.stall_s if k >= self.at else 0.0)

    def refresh_after(self, t: float) -> int:
        k = super().refresh_after(t)
        return k if k < self.at else max(self.at, super().refresh_after(t - self.stall_s))


STALLS = [(60, 1.0), (300, 0.3), (10, 6.0), (90, 0.26), (200, 0.5), (350, 2.0), (420, 0.4), (120, 3.5), (30, 0.75), (250, 1.2)]
"""(refresh before which the frame clock stalls, for how long): early, late, barely over the
threshold, and to past the run's end."""


@pytest.mark.parametrize(("at", "stall_s"), STALLS)
def test_a_frame_clock_that_stalls_makes_the_run_invalid_naming_the_stall(tmp_path: Path, at: int, stall_s: float) -> None:
    clock, run_s, frame_clock = VirtualClock(), 8.0, StallingFrameClock(at, stall_s)
    t_begin = clock.now()
    with CsvRecord(tmp_path / "display_swaps.csv", SWAP_COLUMNS) as swaps:
        display = WindowDisplay(WindowSettings(size=(64, 48)), frame_clock=frame_clock, swap_log=swaps.write,
                                open_window=lambda settings: FakeWindow(clock, swap_s=2e-4))  # fmt: skip
        display.connect(clock)
        image = 0
        while clock.now() < t_begin + run_s:
            display.present(_image(image % 200), clock.now(), image)
            image += 1
    with CsvRecord(tmp_path / "tracker.csv", SAMPLE_COLUMNS) as tracker:
        for t in np.arange(t_begin, t_begin + run_s, 0.002):
            tracker.write(sample_row(PoseSample(t, t, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))))
    health = run_health(tmp_path, display.refresh_hz, t_begin, t_begin + run_s, None)
    gap_ms = (stall_s + PERIOD) * 1e3
    stalled_at = frame_clock.vblank(at - 1) - t_begin
    assert health["status"] == INVALID
    assert health["reasons"] == [f"the rig stalled: no new image for {gap_ms:.0f} ms from {stalled_at:.1f} s into the run"]
    # the refreshes the stall and the frame clock's start took were not presented
    assert health["display"]["missed_refreshes"] == pytest.approx((stall_s + START_DELAY_S) * 60.0, abs=1.0)
