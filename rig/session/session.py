"""One run of the rig: tracker samples -> predictor -> renderer -> display -> camera, on one clock.

The session handles events in time order against the devices' protocols
(`rig.devices.protocols`), whatever implements them: tracker samples reach the predictor (and
`tracker.csv`) once they have arrived; application frames start when the timing policy says the
renderer is ready, and ask the predictor for the pose at the time the photon target says
(`rig.session.timing.PhotonTarget`) of the refresh they expect to reach; at every refresh the
renderer's own work happens (`rig.session.timing`), the refresh is logged (with whether it missed,
repeating the last image), the camera's finished frames go to the run's film, and the instruments
beside the rig record up to the present.

On a virtual clock that is a simulation, deterministic for a seed; on a monotonic clock, waiting
means sleeping until an event is due. Every file is written as the run goes (`rig.session.run_record`),
so an interrupted run leaves a readable record.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from predictors import Pose, PoseSample, Predictor, sample_row
from rig.clock import Clock
from rig.devices.protocols import NO_IMAGE, Camera, Display, Instrument, TrackerSource
from rig.errors import RigError
from rig.writers import CsvRecord
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, DisplayFrameResult, Renderer, RenderSetup
from rig.session.run_record import RunRecord
from rig.session.photon_target import PhotonTarget
from rig.session.timing import CostModel, TimingPolicy

Progress = Callable[[float, float], None]


@dataclass(frozen=True)
class ShownImage:
    """What one image on the display is: the x drawn, the display row it lights, the newest sensor
    time behind it, and what the work that made it cost on the clock (and where that figure came from)."""

    x_m: float
    row_fraction: float
    t_sensor_newest: float
    cost_s: float
    cost_source: str


@dataclass
class SessionLog:
    """What a run showed: every image by id, the id each refresh showed (NO_IMAGE: dark), and what
    the application frames cost."""

    shown: dict[int, ShownImage] = field(default_factory=dict)
    content: list[int] = field(default_factory=list)
    app_costs_s: list[float] = field(default_factory=list)
    """What each application frame cost on the clock."""


@dataclass
class SessionParts:
    """What a run is made of: the clock, the devices, the predictor, and the renderer with its
    setup, timing policy, application-frame cost model and photon target."""

    clock: Clock
    tracker: TrackerSource
    predictor: Predictor
    renderer: Renderer
    render_setup: RenderSetup
    timing: TimingPolicy
    app_cost: CostModel
    display: Display
    camera: Camera | None = None
    instruments: Sequence[Instrument] = ()
    target: PhotonTarget = PhotonTarget()


class SampleFeed:
    """Hands arrived tracker samples to the predictor and to the record."""

    def __init__(self, tracker: TrackerSource, predictor: Predictor, record: CsvRecord) -> None:
        self._tracker = tracker
        self._predictor = predictor
        self._record = record
        self.newest_sensor_time = -math.inf

    def deliver(self, samples: list[PoseSample] | None = None) -> None:
        """Take `samples`, or every sample that has arrived by now."""
        for sample in self._tracker.poll() if samples is None else samples:
            self._predictor.update(sample)
            self._record.write(sample_row(sample))
            self.newest_sensor_time = max(self.newest_sensor_time, sample.t_sensor)

    def predict(self, t: float) -> Pose:
        if self.newest_sensor_time == -math.inf:
            raise RigError("the renderer asked for a pose before any tracker sample arrived; increase the warm-up")
        return self._predictor.predict(t)


class Session:
    """One run from `t_begin` to `t_end` on the parts' clock, recorded into `record`; call `run()` once."""

    def __init__(
        self,
        parts: SessionParts,
        t_begin: float,
        t_end: float,
        record: RunRecord,
        progress: Progress | None = None,
        live: bool = False,
    ) -> None:
        self.parts = parts
        self.t_begin = t_begin
        self.t_end = t_end
        self.live = live
        """A live run: its span counts from when its devices are connected (opening a window and
        finding a tracker take as long as they take) rather than from `t_begin` as given, and the
        samples that arrive after the last application frame took any are recorded too, up to
        closing the tracker (nothing a live tracker sent is lost)."""
        self.record = record
        self.progress = progress
        self.display = parts.display
        self.renderer = parts.renderer
        self.feed = SampleFeed(parts.tracker, parts.predictor, record.tracker)
        self.row_estimate = 0.5
        """The display row the sphere was last drawn at: where the next image's photons are expected."""
        self.log = SessionLog()
        self._app_frames = 0
        self._last_cost = math.nan

    def run(self) -> SessionLog:
        """Connect everything, run to `t_end`, release everything (on any exit); what was shown."""
        parts = self.parts
        with contextlib.ExitStack() as stack:
            devices = [parts.tracker, parts.display, *([parts.camera] if parts.camera else []), *parts.instruments]
            for device in devices:
                device.connect(parts.clock)
                stack.callback(device.close)
                if device is parts.tracker and self.live:
                    stack.callback(self._record_late_samples)
                if device is parts.camera:
                    self.record.open_film(parts.camera.fps, parts.camera.width, parts.camera.height)
                    stack.callback(self._record_camera)  # the frames since the last refresh, before the camera closes
            parts.renderer.open(parts.render_setup)
            stack.callback(parts.renderer.close)
            if self.live:
                shift = parts.clock.now() - self.t_begin
                self.t_begin, self.t_end = self.t_begin + shift, self.t_end + shift
            self._last_cost = parts.app_cost.expected_s(1.0 / parts.display.refresh_hz)  # the refresh as connected
            self._loop()
        return self.log

    def show(
        self, image: np.ndarray | None, t_ready: float, image_id: int, position: np.ndarray, cost_s: float, cost_source: str
    ) -> int:
        """Hand the display an image drawn at `position`, ready at `t_ready` after work that cost
        `cost_s` (`cost_source`: measured or modelled); the refresh it appears at."""
        if image is None:
            raise RigError(f"renderer {self.renderer.name!r} returned no image for a frame it was to display")
        self.row_estimate = self.parts.render_setup.row_fraction(position)
        self.log.shown[image_id] = ShownImage(
            float(position[0]), self.row_estimate, self.feed.newest_sensor_time, float(cost_s), cost_source
        )
        return self.display.present(image, t_ready, image_id)

    def compose(self, k: int, ready: int) -> DisplayFrameResult:
        """The renderer's composed image for refresh k from application frame `ready`."""
        self.feed.deliver()
        request = DisplayFrameRequest(k, self.display.vblank_time(k), self.photon_target(k), self.feed.predict, ready)
        return self.renderer.render_display_frame(request)

    def photon_target(self, k: int) -> float:
        """The instant refresh k's pose is predicted for, at the row the sphere was last drawn at."""
        return self.parts.target.time(self.display, k, self.row_estimate)

    def _loop(self) -> None:
        clock, display, timing = self.parts.clock, self.display, self.parts.timing
        self.feed.deliver(self.parts.tracker.wait(self.t_end - clock.now()))
        if self.feed.newest_sensor_time == -math.inf:
            raise RigError("no tracker sample arrived during the run; check the tracker's connection and settings")
        next_app_start = max(self.t_begin, clock.now())
        k = 0
        while display.vblank_time(k) <= self.t_end:
            t_refresh = timing.refresh_start(display, k)
            while next_app_start <= t_refresh:
                next_app_start = self._app_frame(next_app_start)
            clock.wait_until(t_refresh)
            timing.at_refresh(self, k, max(t_refresh, clock.now()))
            self._log_refresh(k)
            self._record_camera()
            for instrument in self.parts.instruments:
                instrument.poll()
            if self.progress is not None:
                span = self.t_end - self.t_begin
                self.progress(min(display.vblank_time(k) - self.t_begin, span), span)
            k += 1
        clock.wait_until(self.t_end)
        for instrument in self.parts.instruments:
            instrument.finish()

    def _app_frame(self, start: float) -> float:
        """Render application frame at `start`; when the next one starts."""
        index = self._app_frames
        self.parts.clock.wait_until(start)
        start = max(start, self.parts.clock.now())  # on a live clock work may start late
        self.feed.deliver()
        display = self.display
        t_photon = self.photon_target(display.refresh_after(start + self._last_cost))
        result = self.renderer.render_app_frame(AppFrameRequest(index, start, t_photon, self.feed.predict))
        cost = self.parts.app_cost.charge(result.cost_s)
        finish = start + cost
        self._last_cost = cost
        self.log.app_costs_s.append(cost)
        position = result.pose.position
        self.record.app_frames.write(
            [index, start, cost, self.parts.app_cost.source, finish, t_photon, self.feed.newest_sensor_time, *position.tolist()]
        )
        self._app_frames += 1
        return self.parts.timing.app_frame_done(self, index, result, finish, cost, self.parts.app_cost.source)

    def _log_refresh(self, k: int) -> None:
        """Log refresh k; it missed if it repeats the previous refresh's image."""
        image_id = self.display.shown(k)
        missed = bool(self.log.content) and self.log.content[-1] == image_id
        self.log.content.append(image_id)
        if image_id == NO_IMAGE:
            return
        shown = self.log.shown[image_id]
        t_photon = self.display.photon_time(k, shown.row_fraction)
        delay_ms = (t_photon - shown.t_sensor_newest) * 1e3
        self.record.display_frames.write([
            k, self.display.vblank_time(k), image_id, shown.row_fraction, t_photon, shown.t_sensor_newest, delay_ms, shown.x_m,
            int(missed), shown.cost_s, shown.cost_source,
        ])  # fmt: skip

    def _record_late_samples(self) -> None:
        try:
            late = self.parts.tracker.poll()
        except RigError:
            return  # a source that failed has nothing more to give; its failure is the run's
        for sample in late:
            self.record.tracker.write(sample_row(sample))

    def _record_camera(self) -> None:
        if self.parts.camera is None or self.record.film is None:
            return
        for frame in self.parts.camera.poll():
            self.record.film.write(frame)
