"""A live run: the session of a simulated run (`rig.session.Session`) on the monotonic clock, with a
real tracker, a predictor, a renderer and a display (an on-screen window, or an external renderer
through LSL), and where given a camera and instruments (the rig board).

The run's folder gets what a simulated run writes (`tracker.csv`, `app_frames.csv`,
`display_frames.csv`, and with a camera its film, `video.avi` and `camera_frames.csv`), and beside it
`published_poses.csv` (every display frame's pose with the photon time it was predicted for and the
newest sample behind it, also pushed on the `RigPose` LSL outlet), the display's own log
(`display_swaps.csv` for a window, `renderer_markers.csv` for an external renderer) and at the end
`live.json` (each device's report, the film's, why the run ended, and the run's health with its
verdict, `rig.live.health`). Every row is written as it happens; samples that arrive after the
session last took any are written when it ends. A `Watchdog` instrument ends the run with a clear
message when the tracker or the camera goes away (`fault()`; what was recorded stays); so does
closing the window. With `until_still` the run also ends, normally, once the pendulum has stopped
swinging.
"""

from __future__ import annotations

import contextlib
import json
from dataclasses import asdict
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

import predictors
from rig.clock import Clock, MonotonicClock
from rig.devices.protocols import Camera, Display, Instrument, TrackerSource
from rig.devices.registry import make_tracker
from rig.devices.tap import TappedTracker
from rig.devices.window import SWAP_COLUMNS, FrameClock, WindowDisplay
from rig.errors import RigError
from rig.live.config import EXTERNAL, LiveConfig
from rig.live.files import LIVE_FILE, MARKERS_FILE, PUBLISHED_FILE, SWAPS_FILE
from rig.live.health import run_health
from rig.live.still import RunEnded, SwingWatch
from rig.live.view import View, view_from_positions
from rig.lsl import MARKER_COLUMNS, PUBLISHED_COLUMNS, ExternalRenderer, LslPublisher, MarkerDisplay, PublishingRenderer
from rig.writers import CsvRecord
from rig.render import RenderSetup, make_renderer
from rig.session import PhotonTarget, RunRecord, Session, SessionParts, cost_model, timing_for
from rig.session.session import Progress

FRAMING_S = 2.0
TRACKER_SILENCE_S = 1.0
"""A tracker silent this long after its link was lost has been unplugged: the run ends."""


class Watchdog:
    """The instrument beside a live run: it tells `on_connected(display)` once everything is open,
    and ends the run when a device has gone (a tracker lost and silent for TRACKER_SILENCE_S, a
    camera that stopped delivering) or, with a swing watch, once the pendulum has stopped."""

    def __init__(
        self, tracker: TrackerSource, camera: Camera | None, display: Display, on_connected: Callable[[Display], None],
        swing: SwingWatch | None = None,
    ) -> None:  # fmt: skip
        self._tracker = tracker
        self._camera = camera
        self._display = display
        self._on_connected = on_connected
        self._swing = swing
        self._clock: Clock | None = None

    def connect(self, clock: Clock) -> None:
        self._clock = clock
        self._on_connected(self._display)

    def poll(self) -> None:
        if self._swing is not None and self._swing.stopped:
            raise RunEnded("the pendulum stopped swinging")
        lost = self._tracker.fault()
        if lost is not None and self._clock.now() - lost.since > TRACKER_SILENCE_S:
            raise RigError(f"{lost.reason} and has not come back; the run ended")
        gone = self._camera.fault() if self._camera is not None else None
        if gone is not None:
            raise RigError(f"{gone.reason} at {gone.since:.3f} s; the run ended")

    def finish(self) -> None:
        """Nothing to complete."""

    def close(self) -> None:
        """Nothing to release."""


def write_summary(out_dir: Path, summary: dict[str, Any]) -> Path:
    """The run's summary as `live.json` in `out_dir` (rewritten when the analysis adds to it)."""
    path = Path(out_dir) / LIVE_FILE
    path.write_text(json.dumps(summary, indent=1, default=str) + "\n", encoding="utf-8")
    return path


def frame_view(tracker_spec: str, clock: MonotonicClock, width: int, height: int, mirror: bool, seconds: float = FRAMING_S) -> View:
    """The view framing the swing the tracker sees for `seconds` (`rig.live.view`)."""
    tracker = make_tracker(tracker_spec)
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
    instruments: Sequence[Instrument] = (),
    clock: MonotonicClock | None = None,
    overwrite: bool = False,
    progress: Progress | None = None,
    on_connected: Callable[[Display], None] = lambda display: None,
) -> dict[str, Any]:
    """Run `config` live into `out_dir` and return its summary (live.json's content). `frame_clock`
    paces the window instead of the monitor (the self-test's, under a virtual X server); `camera`
    films the run into its record and is watched; `instruments` record beside it (the rig board);
    `view` frames the renderer (None: framed from the tracker first); `on_connected(display)` is
    called once everything is open."""
    clock = clock or MonotonicClock()
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RigError(f"cannot make the output folder {out_dir}: {error.strerror}") from None
    predictor = predictors.make(config.predictor, **config.predictor_params)
    external = config.renderer == EXTERNAL
    renderer = ExternalRenderer() if external else make_renderer(config.renderer)
    width, height = (640, 480) if external else config.window.size
    if view is None:
        view = frame_view(config.tracker, clock, width, height, config.mirror)
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
                                    swap_log=swaps.write)  # fmt: skip
        publisher = LslPublisher(config.streams, display, published)
        swing = SwingWatch() if config.until_still else None
        tracker = TappedTracker(make_tracker(config.tracker), publisher.samples, *([swing] if swing else []))
        setup = RenderSetup(width=display.width, height=display.height, world_to_clip=view.world_to_clip,
                            sphere_radius_m=view.sphere_radius_m, scene_triangles=config.scene_triangles, wait_for_gpu=True)  # fmt: skip
        parts = SessionParts(
            clock=clock,
            tracker=tracker,
            predictor=predictor,
            renderer=PublishingRenderer(renderer, publisher, clock),
            render_setup=setup,
            timing=timing_for(renderer, cost_model(None)),
            app_cost=cost_model(None),
            display=display,
            camera=camera,
            instruments=[*instruments, Watchdog(tracker, camera, display, on_connected, swing)],
            target=PhotonTarget(config.photon_target, config.persistence),
        )
        record = files.enter_context(RunRecord(out_dir, overwrite=overwrite))
        session = Session(parts, clock.now(), clock.now() + config.duration_s, record, progress, live=True)
        try:
            session.run()
            ended = "completed"
        except RunEnded as reason:
            ended = str(reason)
        except RigError as error:
            ended = str(error)
            raise
        finally:
            record.close()
            summary = {
                "tracker": config.tracker, "renderer": config.renderer, "predictor": config.predictor,
                "duration_s": config.duration_s, "ended": ended, "display": display.report(),
                "tracker_report": tracker.report(), "camera": camera.report() if camera is not None else None,
                "film": record.film.report() if record.film is not None else None,
                "lsl": asdict(config.streams) if config.streams else None,
                "view": {"world_to_clip": view.world_to_clip.tolist(), "sphere_radius_m": view.sphere_radius_m},
            }  # fmt: skip
            summary["health"] = run_health(out_dir, display.refresh_hz, session.t_begin,
                                           min(session.t_end, clock.now()), summary["film"])  # fmt: skip
            write_summary(out_dir, summary)
    return summary
