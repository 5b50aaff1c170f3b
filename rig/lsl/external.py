"""An external renderer measured through LSL: the rig predicts and publishes, the renderer draws.

`ExternalRenderer` stands where the rig's own renderer would: one application frame per refresh of
the external renderer's display, asking the predictor for the pose at that refresh's photon time.
It draws nothing itself (its image is a one-pixel placeholder no display shows); a
`PublishingRenderer` around it pushes the pose on `RigPose`.

`MarkerDisplay` is that display as the rig sees it: the refreshes are fitted (`RefreshModel`) to the
swap times the renderer publishes on `RigRendererMarkers`, mapped onto the rig clock with LSL's
clock correction, and kept up to date by every later marker. Every marker is written to
`renderer_markers.csv` as it arrives (`MARKER_COLUMNS`): which published frame was swapped in and
when, on the rig clock. What each refresh showed is known only once its marker has arrived, after
the refresh, so `shown(k)` answers NO_IMAGE and the run's display log is this marker file (joined
with the published poses, `rig.live.log_latency`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from rig.clock import Clock
from rig.devices.protocols import NO_IMAGE
from rig.devices.trackers.lsl_tracker import lsl_origin, open_inlet, pylsl, resolve_streams, time_correction
from rig.devices.window.refresh import RefreshModel
from rig.errors import RigError
from rig.lsl.streams import MARKER_CHANNELS, StreamNames
from rig.writers import CsvRecord
from rig.render.protocol import AppFrameRequest, AppFrameResult, DisplayFrameRequest, DisplayFrameResult, RenderSetup

MARKER_COLUMNS = ("frame", "t_swap", "refresh")
RESOLVE_TIMEOUT_S = 10.0
CALIBRATION_MARKERS = 60
CALIBRATION_TIMEOUT_S = 10.0
CORRECTION_INTERVAL_S = 1.0
_PLACEHOLDER = np.zeros((1, 1, 3), dtype=np.uint8)


class ExternalRenderer:
    """The rig's side of an external renderer; see the module docstring."""

    name = "external"
    per_display_frame = False

    def open(self, setup: RenderSetup) -> None:
        """Nothing to open: the renderer is another program."""

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        started = time.perf_counter()
        pose = request.predict(request.t_photon)
        return AppFrameResult(time.perf_counter() - started, pose, _PLACEHOLDER)

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        raise RigError("the external renderer shows one image per application frame; it composes nothing per refresh")

    def close(self) -> None:
        """Nothing to close."""


class MarkerDisplay:
    """The external renderer's display, timed by its swap markers; see the module docstring."""

    def __init__(self, names: StreamNames, record: CsvRecord, *, width: int = 640, height: int = 480,
                 scanout_fraction: float = 1.0, nominal_refresh_hz: float = 60.0) -> None:  # fmt: skip
        self.names = names
        self.width, self.height = width, height
        self.refresh_hz = nominal_refresh_hz
        self.scanout_fraction = scanout_fraction
        self.timing_source = "renderer markers"
        self._record = record
        self._inlet: Any = None
        self._clock: Clock | None = None
        self._origin = 0.0
        self._offset = 0.0
        self._next_correction = 0.0
        self._model: RefreshModel | None = None
        self._base = 0
        self._last_present = -1
        self._next_shown = 0
        self.markers = 0

    def connect(self, clock: Clock) -> None:
        """Find the renderer's marker stream and fit its refreshes (RigError if it is not there)."""
        lsl = pylsl()
        streams = resolve_streams(RESOLVE_TIMEOUT_S, self.names.markers)
        if not streams:
            raise RigError(
                f"no renderer publishes the marker stream {self.names.markers!r} (waited {RESOLVE_TIMEOUT_S:g} s): start "
                "the renderer first (examples/external_renderer.py shows what it must publish)"
            )
        if streams[0].channel_count() != len(MARKER_CHANNELS):
            raise RigError(f"the marker stream {self.names.markers!r} must have {len(MARKER_CHANNELS)} channels: frame, t_swap")
        self._clock = clock
        self._origin = lsl_origin(clock)
        self._inlet = lsl.StreamInlet(streams[0], max_buflen=30, recover=False)
        self._correct()
        open_inlet(self._inlet, RESOLVE_TIMEOUT_S)
        swaps: list[float] = []
        deadline = clock.now() + CALIBRATION_TIMEOUT_S
        while len(swaps) < CALIBRATION_MARKERS and clock.now() < deadline:
            swaps.extend(t for _, t in self._pull(0.1))
        if len(swaps) < 3:
            raise RigError(f"the renderer's marker stream {self.names.markers!r} sent {len(swaps)} markers in "
                           f"{CALIBRATION_TIMEOUT_S:g} s; it must publish one at every buffer swap")  # fmt: skip
        self._model = RefreshModel.fit(np.array(swaps), "swap markers")
        self._base = self._model.slot(swaps[-1]) + 1
        self.refresh_hz = self._model.refresh_hz

    def _correct(self) -> None:
        offset, _ = time_correction(self._inlet, 2.0)
        self._offset = offset
        self._next_correction = self._clock.now() + CORRECTION_INTERVAL_S

    def _pull(self, timeout_s: float) -> list[tuple[int, float]]:
        """Markers arrived by now as (frame, rig time of the swap)."""
        lsl = pylsl()
        try:
            values, _ = self._inlet.pull_chunk(timeout=timeout_s)
        except lsl.util.LostError:
            raise RigError(f"the renderer's marker stream {self.names.markers!r} went away; the run ended there") from None
        return [(int(frame), t_swap + self._offset - self._origin) for frame, t_swap in values]

    def _drain(self) -> None:
        for frame, t_swap in self._pull(0.0):
            refresh = self._model.slot(t_swap) - self._base
            self._model.observe(refresh + self._base, t_swap)
            self._record.write([frame, t_swap, refresh])
            self.markers += 1
        if self._clock.now() >= self._next_correction:
            try:
                self._correct()
            except pylsl().util.TimeoutError:
                self._next_correction = self._clock.now() + CORRECTION_INTERVAL_S

    def vblank_time(self, k: int) -> float:
        return float(self._model.vblank(k + self._base))

    def refresh_after(self, t: float) -> int:
        return self._model.refresh_after(t) - self._base

    def photon_time(self, k: int, row_fraction: float) -> float:
        return self.vblank_time(k) + float(np.clip(row_fraction, 0.0, 1.0)) * self.scanout_fraction / self.refresh_hz

    def present(self, image: np.ndarray, t_ready: float, image_id: int) -> int:
        """The refresh the published pose is meant for; the renderer draws it (or not: its markers say)."""
        self._drain()
        self._last_present = max(self.refresh_after(t_ready), self._last_present + 1)
        return self._last_present

    def shown(self, k: int) -> int:
        if k != self._next_shown:
            raise ValueError(f"refresh {k} asked for out of turn; the next one is {self._next_shown}")
        self._next_shown += 1
        self._drain()
        return NO_IMAGE

    def report(self) -> dict[str, Any]:
        return {"display": "external renderer (LSL markers)", "refresh_hz": self.refresh_hz,
                "timing_source": self.timing_source, "markers": self.markers,
                "scanout_fraction": self.scanout_fraction}  # fmt: skip

    def close(self) -> None:
        """Record the markers that came since the last refresh, then close the inlet."""
        if self._inlet is None:
            return
        try:
            if self._model is not None:
                self._drain()
        except RigError:
            pass  # the renderer has gone: what it sent is recorded
        finally:
            self._inlet.close_stream()
            self._inlet = None
