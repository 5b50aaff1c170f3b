"""The rig's LSL outlets (`rig.lsl.streams`): the predicted pose per display frame and the raw
tracker stream, and the wrappers that feed them from a session without the session knowing.

`LslPublisher.samples` taps a tracker source (`rig.devices.tap`): every sample the session takes
is pushed on `RigTracker`. `PublishingRenderer` wraps a renderer: every pose it draws a display
frame with (an application frame of a renderer that shows one image per frame, each composed frame
of one that composes at every refresh) is pushed on `RigPose` with the photon time it was predicted
for, the newest sample behind it and, as its stamp, when the renderer was handed it. Pushing never
blocks.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from predictors import Pose, PoseSample
from rig.clock import Clock
from rig.devices.protocols import Display
from rig.devices.trackers.lsl_tracker import describe_channels, lsl_origin, pose_outlet, pylsl
from rig.lsl.streams import POSE_CHANNELS, POSE_UNITS, StreamNames
from rig.render.protocol import (
    AppFrameRequest,
    AppFrameResult,
    DisplayFrameRequest,
    DisplayFrameResult,
    PredictFn,
    Renderer,
    RenderSetup,
)
from rig.writers import CsvRecord

PUBLISHED_COLUMNS = ("frame", "t_pose", *POSE_CHANNELS[1:])
"""`t_pose`: when the renderer was handed the pose (rig clock); the others as `RigPose`'s channels."""


class LslPublisher:
    """The outlets of one run (none where `names` is None: the poses are only recorded) for the
    frames of `display`, whose refresh the pose stream states (read once the display is connected:
    the outlets open with the renderer, after the devices); `record` (optional) gets every pose
    published, on the rig clock."""

    def __init__(self, names: StreamNames | None, display: Display, record: CsvRecord | None = None) -> None:
        self.names = names
        self.display = display
        self.newest_sensor_time = -math.inf
        self._record = record
        self._clock: Clock | None = None
        self._origin = 0.0
        self._pose: Any = None
        self._tracker: Any = None

    def open(self, clock: Clock, setup: RenderSetup) -> None:
        self._clock = clock
        if self.names is None:
            return
        lsl = pylsl()
        self._origin = lsl_origin(clock)
        source = f"latency-rig-{self.names.pose}"
        refresh_hz = self.display.refresh_hz
        pose = lsl.StreamInfo(self.names.pose, "Pose", len(POSE_CHANNELS), refresh_hz, lsl.cf_double64, source)
        describe_channels(pose, POSE_CHANNELS, POSE_UNITS)
        view = pose.desc().append_child("view")
        view.append_child_value("world_to_clip", " ".join(repr(float(v)) for v in np.asarray(setup.world_to_clip).ravel()))
        view.append_child_value("sphere_radius_m", repr(float(setup.sphere_radius_m)))
        pose.desc().append_child_value("refresh_hz", repr(float(refresh_hz)))
        self._pose = lsl.StreamOutlet(pose)
        self._tracker = pose_outlet(self.names.tracker, 0.0, f"latency-rig-{self.names.tracker}")

    def lsl_time(self, t: float) -> float:
        """A rig time on the LSL clock."""
        return t + self._origin

    def samples(self, samples: list[PoseSample]) -> None:
        for sample in samples:
            if self._tracker is not None:
                self._tracker.push_sample([*sample.position.tolist(), *sample.orientation.tolist()], self.lsl_time(sample.t_sensor))
            self.newest_sensor_time = max(self.newest_sensor_time, sample.t_sensor)

    def pose(self, frame: int, t_photon: float, pose: Pose, t_pose: float) -> None:
        """Publish display frame `frame`'s pose, predicted for `t_photon` and handed over at `t_pose`."""
        values = [float(frame), self.lsl_time(t_photon), self.lsl_time(self.newest_sensor_time), *pose.position.tolist(),
                  *pose.orientation.tolist()]  # fmt: skip
        if self._pose is not None:
            self._pose.push_sample(values, self.lsl_time(t_pose))
        if self._record is not None:
            self._record.write([frame, t_pose, t_photon, self.newest_sensor_time, *values[3:]])

    def close(self) -> None:
        self._pose = self._tracker = None


class PublishingRenderer:
    """A renderer whose display-frame poses are also pushed on the rig's pose outlet; the outlets
    open with the renderer (they need its view) and close with it."""

    def __init__(self, renderer: Renderer, publisher: LslPublisher, clock: Clock) -> None:
        self.renderer = renderer
        self.publisher = publisher
        self.name = renderer.name
        self.per_display_frame = renderer.per_display_frame
        self._clock = clock
        self._t_pose = math.nan

    def open(self, setup: RenderSetup) -> None:
        self.publisher.open(self._clock, setup)
        self.renderer.open(setup)

    def _timed(self, predict: PredictFn) -> PredictFn:
        def timed(t: float) -> Pose:
            pose = predict(t)
            self._t_pose = self._clock.now()
            return pose

        return timed

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        result = self.renderer.render_app_frame(replace(request, predict=self._timed(request.predict)))
        if not self.per_display_frame:
            self.publisher.pose(request.index, request.t_photon, result.pose, self._t_pose)
        return result

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        result = self.renderer.render_display_frame(replace(request, predict=self._timed(request.predict)))
        self.publisher.pose(request.index, request.t_photon, result.pose, self._t_pose)
        return result

    def close(self) -> None:
        try:
            self.renderer.close()
        finally:
            self.publisher.close()
