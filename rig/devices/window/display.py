"""`window`: the rig's images on a real monitor (`rig.devices.protocols.Display`).

Each image handed over is drawn into an on-screen window (`GlWindow`) and the buffers swapped with
vsync on; the call returns once the swap is done, so a frame is paced by the display as a
double-buffered vsync application is. Every swap is timed and written to the swap log as it
happens (`SWAP_COLUMNS`): when the image was ready, drawn, handed to the swap, when the swap came
back, and where the driver offers them, when its vertical blank was (GLX_OML_sync_control) and when
the GPU finished drawing (GL timestamp queries). `timing_source` says which the refresh times come
from.

Refreshes are numbered from the first after `connect`. Their times come from a `RefreshModel`
fitted to the swaps of a calibration run at `connect` and kept up to date by every later swap (or,
given a `FrameClock`, from that clock: virtual X servers draw and read back correctly but do not
pace swaps, so tests pace the window with one). A swap that lands at a later refresh than it was
aimed at is late: the display repeated its previous image meanwhile (a missed refresh).
`vblank_time(k)` is the time refresh k was measured at where an image was swapped for it, and the
model's otherwise. The window is opened by `open_window` (tests give a fake). Rows are lit top to bottom over `scanout_fraction` of the period after the blank
(the modelled scan-out; a monitor's own is not measured here).
"""

from __future__ import annotations

from typing import Any, Callable, NamedTuple, Protocol

import numpy as np

from rig.clock import Clock
from rig.devices.protocols import NO_IMAGE
from rig.devices.window.gl_window import GlWindow, WindowSettings
from rig.devices.window.refresh import RefreshModel
from rig.devices.window.timing_sources import GpuTimestamps, OmlSyncValues
from rig.errors import ConfigError, RigError

CALIBRATION_SWAPS = 90
"""Swaps of a dark image at connect that measure the refresh (1.5 s at 60 Hz)."""
KEEP_MEASURED = 512
EARLY_SWAP_GUARD = 0.1
"""An image held for a later refresh is swapped this share of a period after the blank before it:
a vsync swap then lands at the blank it was held for, not the one before."""


class FrameClock(Protocol):
    """Refresh times given to the window instead of measured: the window waits for refresh k's
    blank before swapping an image aimed at it."""

    refresh_hz: float

    def start(self, clock: Clock) -> None:
        """Refresh 0 is a little after now."""

    def vblank(self, k: int) -> float: ...

    def refresh_after(self, t: float) -> int:
        """The first refresh whose blank is strictly after `t`."""


class SwapRecord(NamedTuple):
    """One swap, a row of the swap log (`SWAP_COLUMNS`): the refresh it was aimed at, the one it
    reached and how many later that was; times on the rig clock, None where not measured."""

    image: int
    aimed_refresh: int
    refresh: int
    late: int
    t_ready: float
    t_drawn: float
    t_swap_call: float
    t_swap: float
    t_blank_driver: float | None
    t_gpu_done: float | None


SWAP_COLUMNS = SwapRecord._fields


class WindowDisplay:
    """A monitor showing the rig's images in a window; see the module docstring."""

    def __init__(
        self,
        settings: WindowSettings = WindowSettings(),
        *,
        scanout_fraction: float = 1.0,
        nominal_refresh_hz: float = 60.0,
        frame_clock: FrameClock | None = None,
        swap_log: Callable[[SwapRecord], None] | None = None,
        open_window: Callable[[WindowSettings], GlWindow] = GlWindow,
    ) -> None:
        if not 0.0 < scanout_fraction <= 1.0:
            raise ConfigError(f"the scan-out fraction is a share of a refresh in (0, 1], got {scanout_fraction!r}")
        self.settings = settings
        self.scanout_fraction = scanout_fraction
        self.width, self.height = settings.size
        self.refresh_hz = frame_clock.refresh_hz if frame_clock is not None else nominal_refresh_hz
        self.timing_source = "not connected"
        self.window: GlWindow | None = None
        self._frame_clock = frame_clock
        self._swap_log = swap_log
        self._open_window = open_window
        self._clock: Clock | None = None
        self._model: RefreshModel | None = None
        self._base = 0
        self._oml: OmlSyncValues | None = None
        self._msc_base = 0
        self._gpu: GpuTimestamps | None = None
        self._measured: dict[int, float] = {}
        self._presents: list[tuple[int, int]] = []
        self._current = NO_IMAGE
        self._next_shown = 0
        self._last_present = -1
        self.swaps = 0
        self.late_swaps = 0

    def connect(self, clock: Clock) -> None:
        """Open the window and measure its refresh (or start the frame clock)."""
        self._clock = clock
        window = self.window = self._open_window(self.settings)
        try:
            self.width, self.height = window.width, window.height
            with window.current():
                glx = window.native_glx()
                if glx is not None:
                    self._oml = OmlSyncValues.open(
                        window.proc_address, window.extension_supported("GLX_OML_sync_control"), *glx, clock
                    )
                self._gpu = GpuTimestamps.open(window.proc_address, set(window.ctx.extensions), clock)
                self._calibrate(clock)
        except BaseException:
            self.close()
            raise

    def _calibrate(self, clock: Clock) -> None:
        window = self.window
        if self._frame_clock is not None:
            self._frame_clock.start(clock)
            self.timing_source = "frame-clock"
            return
        dark = np.zeros((8, 8, 3), dtype=np.uint8)
        times, counts = [], []
        for _ in range(CALIBRATION_SWAPS):
            window.draw(dark)
            window.swap()
            times.append(clock.now())
            if self._oml is not None and (values := self._oml.read()) is not None:
                counts.append(values[0])
                times[-1] = values[1]
        if self._oml is not None and len(counts) == len(times):
            self.timing_source = OmlSyncValues.source
            self._model = RefreshModel(times[-1], float(np.polyfit(counts, times, 1)[0]))
            self._msc_base = counts[-1] + 1
        else:
            self._oml = None
            self.timing_source = "swap-return"
            self._model = RefreshModel.fit(np.array(times))
        self._base = self._model.slot(times[-1]) + 1 if self._oml is None else 1
        self.refresh_hz = self._model.refresh_hz

    @property
    def period_s(self) -> float:
        return 1.0 / self.refresh_hz

    def _predicted(self, k: int) -> float:
        if self._frame_clock is not None:
            return self._frame_clock.vblank(k)
        return float(self._model.vblank(k + self._base))

    def vblank_time(self, k: int) -> float:
        """When refresh k started: as measured where an image was swapped for it, else predicted."""
        measured = self._measured.get(k)
        return measured if measured is not None else self._predicted(k)

    def refresh_after(self, t: float) -> int:
        if self._frame_clock is not None:
            return self._frame_clock.refresh_after(t)
        return self._model.refresh_after(t) - self._base

    def photon_time(self, k: int, row_fraction: float) -> float:
        return self.vblank_time(k) + float(np.clip(row_fraction, 0.0, 1.0)) * self.scanout_fraction * self.period_s

    def present(self, image: np.ndarray, t_ready: float, image_id: int) -> int:
        """Draw `image` and swap it in at the next refresh it can make: at most one new image a
        refresh, and never at a refresh whose content `shown` has already given (an image ready
        early, for a refresh the run has already accounted for up to, waits for that refresh's
        blank); returns once the swap is done, with the refresh it reached."""
        window, clock = self._window(), self._clock
        if window.closing():
            raise RigError("the display window was closed; the run ended there (everything recorded so far is kept)")
        aimed = max(self.refresh_after(max(t_ready, clock.now())), self._last_present + 1, self._next_shown)
        with window.current():
            window.draw(image)
            if self._gpu is not None:
                self._gpu.mark()
            t_drawn = clock.now()
            if self._frame_clock is not None:
                clock.wait_until(self._frame_clock.vblank(aimed))
            else:
                clock.wait_until(self._predicted(aimed - 1) + EARLY_SWAP_GUARD * self.period_s)
            t_call = clock.now()
            window.swap()
            t_swap = clock.now()
            gpu_done = self._gpu.read() if self._gpu is not None else None
        refresh, t_blank = self._reached(aimed, t_swap)
        self._measured[refresh] = t_blank if t_blank is not None else t_swap
        self._measured.pop(refresh - KEEP_MEASURED, None)
        self._presents.append((refresh, image_id))
        self._last_present = refresh
        self.swaps += 1
        self.late_swaps += refresh > aimed
        if self._swap_log is not None:
            times = (t_ready, t_drawn, t_call, t_swap, t_blank, gpu_done)
            self._swap_log(SwapRecord(image_id, aimed, refresh, refresh - aimed, *times))
        return refresh

    def _reached(self, aimed: int, t_swap: float) -> tuple[int, float | None]:
        """The refresh a swap that returned at `t_swap` reached, and the driver's time of its blank."""
        if self._frame_clock is not None:
            return max(aimed, self.refresh_after(t_swap) - 1), None
        if self._oml is not None and (values := self._oml.read()) is not None:
            msc, t_blank = values
            self._model.observe(msc - self._msc_base + self._base, t_blank)
            return max(msc - self._msc_base, self._last_present + 1), t_blank
        refresh = max(self._model.slot(t_swap) - self._base, self._last_present + 1)
        self._model.observe(refresh + self._base, t_swap)
        return refresh, None

    def shown(self, k: int) -> int:
        if k != self._next_shown:
            raise ValueError(f"refresh {k} asked for out of turn; the next one is {self._next_shown}")
        self._next_shown += 1
        while self._presents and self._presents[0][0] <= k:
            self._current = self._presents.pop(0)[1]
        return self._current

    def _window(self) -> GlWindow:
        if self.window is None:
            raise RigError("the window display is not connected")
        return self.window

    def report(self) -> dict[str, Any]:
        """How the display was timed and how many swaps were late, for the run's summary."""
        return {
            "display": "window",
            "size": [self.width, self.height],
            "refresh_hz": self.refresh_hz,
            "timing_source": self.timing_source,
            "gpu_timestamps": self._gpu is not None,
            "scanout_fraction": self.scanout_fraction,
            "swaps": self.swaps,
            "late_swaps": self.late_swaps,
        }

    def close(self) -> None:
        window, self.window = self.window, None
        if window is not None:
            window.close()
