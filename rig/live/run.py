"""A live run: the session of a simulated run (`rig.session.Session`) on the monotonic clock, with a
real tracker, a predictor, a renderer and a display (an on-screen window, or an external renderer
through LSL).

The run's folder gets what a simulated run writes (`tracker.csv`, `app_frames.csv`,
`display_frames.csv`), and beside it `published_poses.csv` (every display frame's pose with the
photon time it was predicted for and the newest sample behind it, also pushed on the `RigPose`
LSL outlet), the display's own log (`display_swaps.csv` for a window, `renderer_markers.csv` for an
external renderer) and at the end `live.json` (devices, timing sources, counts, why it ended).
Every row is written as it happens; samples that arrive after the session last took any are
written when it ends. A `Watchdog` instrument ends the run with a clear message when
the tracker or the camera goes away (what was recorded stays); so does closing the window. With
`until_still` the run also ends, normally, once the pendulum has stopped swinging.
"""

from __future__ import annotations

import contextlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

import predictors
from rig.clock import MonotonicClock
from rig.devices.protocols import Camera, Display
from rig.devices.registry import DeviceContext, make_device
from rig.devices.trackers.stream import TrackerStream
from rig.devices.window import SWAP_COLUMNS, FrameClock, WindowDisplay, WindowSettings
from rig.errors import ConfigError, RigError
from rig.live.still import RunEnded, SwingWatch
from rig.live.view import View, view_from_positions
from rig.lsl import MARKER_COLUMNS, PUBLISHED_COLUMNS, ExternalRenderer, LslPublisher, MarkerDisplay, PublishingRenderer
from rig.lsl import PublishingTracker, StreamNames
from rig.records import CsvRecord
from rig.render import RenderSetup, make_renderer
from rig.session import PhotonTarget, RunRecord, Session, SessionParts, cost_model, timing_for
from rig.session.session import Progress

LIVE_FILE = "live.json"
PUBLISHED_FILE = "published_poses.csv"
SWAPS_FILE = "display_swaps.csv"
MARKERS_FILE = "renderer_markers.csv"
FRAMING_S = 2.0
TRACKER_SILENCE_S = 1.0
"""A tracker silent this long after its link was lost has been unplugged: the run ends."""
EXTERNAL = "external"


@dataclass(frozen=True)
class LiveConfig:
    """One live run: which tracker, renderer (EXTERNAL: another program over LSL) and predictor, how
    long, and how the display's frames are aimed."""

    tracker: str
    renderer: str = "warp"
    predictor: str = "default"
    predictor_params: tuple[tuple[str, Any], ...] = ()
    duration_s: float = 30.0
    window: WindowSettings = WindowSettings()
    scanout_fraction: float = 1.0
    photon_target: str = "photons"
    persistence: float = 1.0
    scene_triangles: int = 0
    streams: StreamNames | None = StreamNames()
    mirror: bool = False
    until_still: bool = False
    """End when the pendulum has stopped swinging (`rig.live.still`), if before the duration."""

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration_s) and self.duration_s > 0):
            raise ConfigError(f"a live run lasts a positive number of seconds, got {self.duration_s!r}")
        if self.renderer == EXTERNAL and self.streams is None:
            raise ConfigError("an external renderer is reached through LSL: the run needs its streams")


@dataclass
class LiveResult:
    out_dir: Path
    summary: dict[str, Any] = field(default_factory=dict)


class Watchdog:
    """The instrument beside a live run: connected last, it starts the camera once everything else
    is open (and tells `on_connected`), and ends the run when a device has gone: a tracker whose link
    was lost and has stayed silent, a camera that stopped delivering."""

    def __init__(
        self, tracker: Any, camera: Camera | None, display: Display, on_connected: Callable[[Display], None],
        swing: SwingWatch | None = None,
    ) -> None:  # fmt: skip
        self._tracker = tracker
        self._swing = swing
        self._camera = camera
        self._display = display
        self._on_connected = on_connected
        self._clock: Any = None

    def connect(self, clock: Any) -> None:
        self._clock = clock
        self._on_connected(self._display)
        if self._camera is not None:
            self._camera.connect(clock)

    def poll(self) -> None:
        if self._swing is not None and self._swing.stopped:
            raise RunEnded("the pendulum stopped swinging")
        stream = self._tracker
        if isinstance(stream, TrackerStream) and stream.events and stream.events[-1].what == "lost":
            if self._clock.now() - stream.events[-1].t > TRACKER_SILENCE_S:
                raise RigError(f"tracker {stream.name} was lost ({stream.events[-1].detail}) and has not come back; the run ended")
        if self._camera is None:
            return
        self._camera.poll()
        failure = getattr(self._camera, "failure", None)
        if failure:
            raise RigError(f"{failure}; the run ended")

    def finish(self) -> None:
        """Nothing to complete."""

    def close(self) -> None:
        if self._camera is not None:
            self._camera.close()


def _record_left_over(tracker: Any, record: RunRecord) -> None:
    """Samples that arrived after the session last took any (it has closed the tracker): recorded too."""
    if isinstance(tracker, TrackerStream):
        for left in tracker.take_queued():
            record.tracker.write(left.sample_row())


def frame_view(tracker_spec: str, clock: MonotonicClock, width: int, height: int, mirror: bool, seconds: float = FRAMING_S) -> View:
    """The view framing the swing the tracker sees for `seconds` (`rig.live.view`)."""
    tracker = make_device("tracker", tracker_spec, DeviceContext())
    tracker.connect(clock)
    positions = []
    try:
        end = clock.now() + seconds
        while clock.now() < end:
            positions.extend(sample.position for sample in tracker.wait(end - clock.now()))
    finally:
        tracker.close()
    return view_from_positions(np.array(positions).reshape(-1, 3), width, height, mirror)


def run_live(
    config: LiveConfig,
    out_dir: Path,
    *,
    view: View | None = None,
    frame_clock: FrameClock | None = None,
    camera: Camera | None = None,
    clock: MonotonicClock | None = None,
    overwrite: bool = False,
    progress: Progress | None = None,
    on_connected: Callable[[Display], None] = lambda display: None,
) -> LiveResult:
    """Run `config` live into `out_dir`. `frame_clock` paces the window instead of the monitor (the
    self-test's, under a virtual X server); `camera` runs beside the session and is watched; `view`
    frames the renderer (None: framed from the tracker first); `on_connected(display)` is called
    once the display is open."""
    clock = clock or MonotonicClock()
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RigError(f"cannot make the output folder {out_dir}: {error.strerror}") from None
    predictor = predictors.make(config.predictor, **dict(config.predictor_params))
    external = config.renderer == EXTERNAL
    renderer = ExternalRenderer() if external else make_renderer(config.renderer)
    width, height = (640, 480) if external else config.window.size
    if view is None:
        view = frame_view(config.tracker, clock, width, height, config.mirror)
    result = LiveResult(out_dir)
    ended = "interrupted"
    with contextlib.ExitStack() as files:
        published = files.enter_context(CsvRecord(out_dir / PUBLISHED_FILE, PUBLISHED_COLUMNS, overwrite=overwrite))
        if external:
            markers = files.enter_context(CsvRecord(out_dir / MARKERS_FILE, MARKER_COLUMNS, overwrite=overwrite))
            display: Display = MarkerDisplay(config.streams, markers, width=width, height=height,
                                             scanout_fraction=config.scanout_fraction)  # fmt: skip
        else:
            swaps = files.enter_context(CsvRecord(out_dir / SWAPS_FILE, SWAP_COLUMNS, overwrite=overwrite))
            display = WindowDisplay(config.window, scanout_fraction=config.scanout_fraction, frame_clock=frame_clock,
                                    swap_log=lambda swap: swaps.write(swap.row()))  # fmt: skip
        publisher = LslPublisher(config.streams, display, published)
        tracker = make_device("tracker", config.tracker, DeviceContext())
        swing = SwingWatch(tracker) if config.until_still else None
        setup = RenderSetup(width=display.width, height=display.height, world_to_clip=view.world_to_clip,
                            sphere_radius_m=view.sphere_radius_m, scene_triangles=config.scene_triangles, wait_for_gpu=True)  # fmt: skip
        parts = SessionParts(
            clock=clock,
            tracker=PublishingTracker(swing or tracker, publisher),
            predictor=predictor,
            renderer=PublishingRenderer(renderer, publisher, clock),
            render_setup=setup,
            timing=timing_for(renderer, cost_model(None)),
            app_cost=cost_model(None),
            display=display,
            instruments=[Watchdog(tracker, camera, display, on_connected, swing)],
            target=PhotonTarget(config.photon_target, config.persistence),
        )
        try:
            with RunRecord(out_dir, None, overwrite=overwrite) as record:
                try:
                    Session(parts, clock.now(), clock.now() + config.duration_s, record, progress, from_connect=True).run()
                finally:
                    _record_left_over(tracker, record)
            ended = "completed"
        except RunEnded as reason:
            ended = str(reason)
        except RigError as error:
            ended = str(error)
            raise
        finally:
            result.summary = {
                "tracker": config.tracker, "renderer": config.renderer, "predictor": config.predictor,
                "duration_s": config.duration_s, "ended": ended,
                "display": display.report() if hasattr(display, "report") else {"display": type(display).__name__},
                "tracker_report": tracker.report() if isinstance(tracker, TrackerStream) else None,
                "camera": camera.report() if camera is not None and hasattr(camera, "report") else None,
                "lsl": {"pose": config.streams.pose, "tracker": config.streams.tracker, "markers": config.streams.markers}
                if config.streams else None,
                "view": {"world_to_clip": view.world_to_clip.tolist(), "sphere_radius_m": view.sphere_radius_m},
            }  # fmt: skip
            (out_dir / LIVE_FILE).write_text(json.dumps(result.summary, indent=1, default=str) + "\n", encoding="utf-8")
    return result
