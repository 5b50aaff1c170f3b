"""The display's pre-flight check: the window a run draws in, opened as the run opens it (its refresh
measured from the swaps of a calibration run, `rig.devices.window`), then images presented for about
a second as a run presents them: the refresh measured from those swaps' own timestamps (the
driver's blank times where it gives them), and whether the swaps were paced, each at its refresh."""

from __future__ import annotations

import numpy as np

from rig.clock import Clock
from rig.devices.window import FrameClock, SwapRecord, WindowDisplay
from rig.devices.window.spec import parse_window_address
from rig.errors import RigError
from rig.preflight.rows import PASS, WARN, CheckRow, failed, graded

PRESENT_S = 1.0
"""How long images are presented for after the window's calibration."""
MISSED_WARN = 0.02
"""More than this share of swaps late (their refresh missed): the run will repeat images."""
MISSED_FAIL = 0.25
REFRESH_AGREEMENT = 0.01
"""The refresh measured from the presented swaps and the window's calibration agree within this share."""


def check_display(spec: str, clock: Clock, frame_clock: FrameClock | None = None) -> list[CheckRow]:
    """Open the window `spec` (the part after `window`), present images for PRESENT_S and close it;
    `frame_clock` paces it instead of the monitor (under a virtual X server)."""
    settings, scanout = parse_window_address(spec.removeprefix("window").removeprefix(":"))
    swaps: list[SwapRecord] = []
    display = WindowDisplay(settings, scanout_fraction=scanout, frame_clock=frame_clock, swap_log=swaps.append)
    try:
        display.connect(clock)
    except RigError as error:  # no window, or swaps no refresh explains: the message says what to do
        return [failed("display", "opens, swaps paced", str(error), "as the message says")]
    try:
        images = [np.full((display.height, display.width, 3), level, dtype=np.uint8) for level in (0, 32)]
        count = max(3, round(PRESENT_S * display.refresh_hz))
        for k in range(count):
            display.present(images[k % 2], clock.now(), k)
    finally:
        display.close()
    return _rows(swaps, display)


def _rows(swaps: list[SwapRecord], display: WindowDisplay) -> list[CheckRow]:
    times = np.array([s.t_blank_driver if s.t_blank_driver is not None else s.t_swap for s in swaps])
    refreshes = np.array([s.refresh for s in swaps])
    per_refresh = np.diff(times) / np.maximum(np.diff(refreshes), 1)
    measured_hz = 1.0 / float(np.median(per_refresh))
    source = display.timing_source
    values = {"refresh_hz": measured_hz, "calibrated_hz": display.refresh_hz, "timing_source": source, "swaps": len(swaps)}
    agree = abs(measured_hz - display.refresh_hz) <= REFRESH_AGREEMENT * display.refresh_hz
    refresh = CheckRow(
        "display", "refresh", PASS if agree else WARN,
        f"{measured_hz:.2f} Hz from {len(swaps)} swaps ({source}); calibrated {display.refresh_hz:.2f} Hz",
        "" if agree else "the refresh drifted between calibration and use: close programs loading the GPU, turn the compositor off",
        values,
    )  # fmt: skip
    late = sum(s.refresh > s.aimed_refresh for s in swaps)
    status = graded(1.0 - late / len(swaps), 1.0 - MISSED_WARN, 1.0 - MISSED_FAIL)
    paced = CheckRow(
        "display", "swaps paced", status, f"{late} of {len(swaps)} swaps missed their refresh",
        "" if status == PASS else "close programs loading the CPU or GPU, turn the compositor off or use full screen",
        {"late_swaps": late, "swaps": len(swaps)},
    )  # fmt: skip
    return [refresh, paced]
