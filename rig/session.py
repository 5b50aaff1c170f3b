"""A simulated rig run: pendulum -> tracker -> predictor -> renderer -> display -> camera -> video.

Everything runs on one virtual clock. The rig starts `warmup_s` before the camera so the tracker,
predictor and display are in their steady state when filming begins at t = 0. Events are handled in
time order: tracker samples are delivered to the predictor when they arrive, application frames
start when the renderer is ready, display frames happen at every vertical blank, and camera frames
are exposed as soon as everything they see is known.

A run writes into its output folder as it goes, so an interrupted run leaves a readable record:

* `tracker.csv` every sample as it reaches the host;
* `app_frames.csv` every application frame (start, cost and where it came from, pose drawn);
* `display_frames.csv` every refresh (what it shows, its photon time, the delay from sensor to photons);
* `video.avi` the camera's video;
* `board/` with a simulated board (config.board): its LED and encoder recording, as a real board's
  (rig.sim.board);
* `truth.json` at the end: the true effective latency and the whole configuration.
"""

from __future__ import annotations

import csv
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

import cv2
import numpy as np

import predictors
from predictors import Pose, PoseSample
from rig.devices.recording import FILES, METADATA
from rig.errors import ConfigError, RigError
from rig.render import make_renderer
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, Renderer, RenderSetup
from rig.sim.bench import BenchLayout, make_layout
from rig.sim.board import BOARD_FOLDER, SimulatedBoard, SimulatedBoardConfig
from rig.sim.camera import CameraConfig, CameraSensor, VideoFileWriter
from rig.sim.display import Display, DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import TrackerConfig, TrackerCsvWriter, simulate_tracker
from rig.truth import effective_latency

Progress = Callable[[float, float], None]
NO_IMAGE = -1
RUN_FILES = ("video.avi", "truth.json", "tracker.csv", "app_frames.csv", "display_frames.csv", BOARD_FOLDER)
DEFAULT_WARP_MS = 2.0
"""Modelled server cost per display frame of a per-display-frame (warp) renderer whose run gives
none: a GPU's point warp of a display-sized image, well inside a refresh. Software OpenGL takes
longer; `rig bench renderers` reports the real cost beside the modelled one."""
_PRUNE_REFRESHES = 4


@dataclass(frozen=True)
class SimulationConfig:
    """Everything that defines a simulated run; the same config and seed give the same video."""

    duration_s: float = 10.0
    seed: int = 0
    pendulum: PendulumConfig = field(default_factory=PendulumConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    display: DisplayConfig = field(default_factory=DisplayConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    renderer: str = "direct"
    predictor: str = "hold"
    predictor_params: dict[str, Any] = field(default_factory=dict)
    scene_triangles: int = 0
    app_frame_ms: float | None = 5.0
    warp_ms: float | None = None
    warmup_s: float = 0.5
    board: SimulatedBoardConfig | None = None

    def __post_init__(self) -> None:
        if not (np.isfinite(self.duration_s) and 0.5 <= self.duration_s <= 3600.0):
            raise ConfigError(f"duration must be 0.5-3600 s, got {self.duration_s}")
        if self.scene_triangles < 0:
            raise ConfigError(f"scene triangles must be >= 0, got {self.scene_triangles}")
        if self.app_frame_ms is not None and not (np.isfinite(self.app_frame_ms) and self.app_frame_ms > 0):
            raise ConfigError(f"application frame cost must be a positive number of ms, got {self.app_frame_ms}")
        if self.warp_ms is not None and not (np.isfinite(self.warp_ms) and self.warp_ms > 0):
            raise ConfigError(f"warp cost must be a positive number of ms, got {self.warp_ms}")
        if self.warmup_s < 0:
            raise ConfigError(f"warm-up must be >= 0 s, got {self.warmup_s}")
        release = self.pendulum.release_s
        swing_s = self.pendulum.small_angle_period_s
        if release is not None and not 0.0 <= release <= self.duration_s - swing_s:
            raise ConfigError(
                f"the pendulum's release at {release:g} s must fall within the filmed span with at least one "
                f"swing ({swing_s:.2f} s) filmed after it: release it between 0 and "
                f"{self.duration_s - swing_s:.2f} s, or film longer"
            )
        if self.board is not None and not 0.0 < self.board.blink_start_s < self.board.blink_end_s <= self.duration_s:
            raise ConfigError(
                f"the blink ({self.board.blink_start_s:g} s to {self.board.blink_end_s:g} s) must fall within the "
                f"filmed span (0 to {self.duration_s:g} s): start it after 0 s and film at least until it ends"
            )

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class _Shown:
    """What one image on the display is: the pose drawn and the newest sensor time behind it."""

    x_m: float
    row_fraction: float
    t_sensor_newest: float


@dataclass(frozen=True)
class SimulationResult:
    out_dir: Path
    video_path: Path
    truth: dict[str, Any]


class _SampleFeed:
    """Delivers tracker samples to the predictor (and to disk) as they arrive on the clock."""

    def __init__(self, samples: list[PoseSample], predictor: Any, writer: TrackerCsvWriter) -> None:
        self._samples = samples
        self._next = 0
        self._predictor = predictor
        self._writer = writer
        self.newest_sensor_time = -np.inf
        if not samples:
            raise RigError("the tracker produced no samples; check its rate and dropout settings")
        self.first_arrival = samples[0].t_arrival

    def deliver_until(self, t: float) -> None:
        while self._next < len(self._samples) and self._samples[self._next].t_arrival <= t:
            sample = self._samples[self._next]
            self._predictor.update(sample)
            self._writer.write(sample)
            self.newest_sensor_time = max(self.newest_sensor_time, sample.t_sensor)
            self._next += 1

    def predict(self, t: float) -> Pose:
        if self.newest_sensor_time == -np.inf:
            raise RigError("the renderer asked for a pose before any tracker sample arrived; increase the warm-up")
        return self._predictor.predict(t)


class _CsvLog:
    """A CSV file flushed row by row, so an interrupted run keeps every row written."""

    def __init__(self, path: Path, header: list[str]) -> None:
        self._file = open(path, "w", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow(header)
        self._file.flush()

    def write(self, row: list[Any]) -> None:
        self._writer.writerow([repr(v) if isinstance(v, float) else v for v in row])
        self._file.flush()

    def close(self) -> None:
        self._file.close()


class Simulation:
    """One simulated run; call `run()` once."""

    def __init__(
        self,
        config: SimulationConfig,
        out_dir: Path,
        progress: Progress | None = None,
        overwrite: bool = False,
    ) -> None:
        self.config = config
        self.overwrite = overwrite
        self.out_dir = Path(out_dir)
        self.progress = progress
        c = config
        self.t_begin = -c.warmup_s
        self.t_end = c.duration_s
        # the truth's latency search (rig.truth) looks up to half a period past the filmed span
        swing_s = c.pendulum.small_angle_period_s
        self.pendulum = Pendulum(c.pendulum, t_start=self.t_begin - 1.0, t_end=self.t_end + 1.0 + swing_s)
        self.display = Display(DisplayConfig(**{**asdict(c.display), "t0": self.t_begin}))
        self.layout: BenchLayout = make_layout(self.pendulum, c.camera, c.display)
        self.sensor = CameraSensor(c.camera, seed=c.seed + 1)
        self.predictor = predictors.make(c.predictor, **c.predictor_params)
        self.renderer: Renderer = make_renderer(c.renderer)
        self.frame_times = np.arange(0.0, c.duration_s - c.camera.exposure, 1.0 / c.camera.fps)
        self.board: SimulatedBoard | None = None
        self._panel_rows = (np.arange(self.layout.panel[3]) + 0.5) / self.layout.panel[3]

    def run(self) -> SimulationResult:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        existing = [name for name in RUN_FILES if (self.out_dir / name).exists()]
        if existing and not self.overwrite:
            raise RigError(
                f"{self.out_dir} already holds a run ({', '.join(existing)}); "
                "choose another output folder or pass --overwrite"
            )
        if self.overwrite:
            self._remove_board_recording()
        c = self.config
        samples = simulate_tracker(self.pendulum, c.tracker, self.t_begin, self.t_end, seed=c.seed)
        video_path = self.out_dir / "video.avi"
        shown: dict[int, _Shown] = {}
        content: list[int] = []
        with (
            TrackerCsvWriter(self.out_dir / "tracker.csv", overwrite=self.overwrite) as tracker_log,
            VideoFileWriter(video_path, c.camera.fps, c.camera.width, c.camera.height) as video,
        ):
            feed = _SampleFeed(samples, self.predictor, tracker_log)
            app_log = _CsvLog(
                self.out_dir / "app_frames.csv",
                ["index", "t_start", "cost_s", "cost_source", "t_finish", "t_photon_target", "t_sensor_newest", "x", "y", "z"],
            )
            display_log = _CsvLog(
                self.out_dir / "display_frames.csv",
                ["refresh", "t_vblank", "image", "row_fraction", "t_photon", "t_sensor_newest", "delay_ms", "x"],
            )
            try:
                if c.board is not None:
                    self.board = SimulatedBoard(c.board, self.pendulum, self.t_begin, self.t_end, self.out_dir / BOARD_FOLDER)
                self._open_renderer()
                self._loop(feed, video, shown, content, app_log, display_log)
                if self.board is not None:
                    self.board.finish()
            finally:
                self.renderer.close()
                app_log.close()
                display_log.close()
                if self.board is not None:
                    self.board.close()
        truth = self._truth(shown, content)
        (self.out_dir / "truth.json").write_text(json.dumps(truth, indent=2))
        return SimulationResult(self.out_dir, video_path, truth)

    def _remove_board_recording(self) -> None:
        """Remove a previous run's board recording (only the files a recording holds)."""
        folder = self.out_dir / BOARD_FOLDER
        for name in [name for name, _ in FILES.values()] + [METADATA]:
            (folder / name).unlink(missing_ok=True)
        if folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()

    def _open_renderer(self) -> None:
        c = self.config
        self.renderer.open(
            RenderSetup(
                width=c.display.width,
                height=c.display.height,
                world_to_clip=self.layout.world_to_clip,
                sphere_radius_m=self.layout.sphere_radius_m,
                scene_triangles=c.scene_triangles,
                app_frame_ms=c.app_frame_ms,
                warp_ms=self._warp_ms(),
                seed=c.seed,
            )
        )

    def _warp_ms(self) -> float | None:
        """The server cost per display frame this run models: the config's, else DEFAULT_WARP_MS
        for a per-display-frame renderer (a direct renderer has no server)."""
        if self.config.warp_ms is None and self.renderer.per_display_frame:
            return DEFAULT_WARP_MS
        return self.config.warp_ms

    def _loop(
        self,
        feed: _SampleFeed,
        video: VideoFileWriter,
        shown: dict[int, _Shown],
        content: list[int],
        app_log: _CsvLog,
        display_log: _CsvLog,
    ) -> None:
        c = self.config
        display = self.display
        per_display = self.renderer.per_display_frame
        server_s = self._warp_ms() / 1e3 if per_display else 0.0
        panel_images: dict[int, np.ndarray] = {}
        app_finish: list[float] = []
        presents: list[tuple[int, int]] = []
        next_app_start = max(self.t_begin, feed.first_arrival)
        last_cost = c.app_frame_ms / 1e3 if c.app_frame_ms is not None else display.period_s
        row_estimate = 0.5
        current_image = NO_IMAGE
        next_camera = 0
        last_present = -1
        k = 0
        while display.vblank_time(k) <= self.t_end:
            t_display_event = display.vblank_time(k) - server_s
            while next_app_start <= t_display_event:
                j = len(app_finish)
                feed.deliver_until(next_app_start)
                present_estimate = display.refresh_after(next_app_start + last_cost)
                t_photon = display.photon_time(present_estimate, row_estimate)
                result = self.renderer.render_app_frame(AppFrameRequest(j, next_app_start, t_photon, feed.predict))
                newest = feed.newest_sensor_time
                finish = next_app_start + result.cost_s
                app_finish.append(finish)
                last_cost = result.cost_s
                p = result.pose.position
                app_log.write([j, next_app_start, result.cost_s, result.cost_source, finish, t_photon, newest, *p.tolist()])
                if per_display:
                    next_app_start = finish
                else:
                    row_estimate = self.layout.display_row_fraction(p)
                    shown[j] = _Shown(float(p[0]), row_estimate, newest)
                    panel_images[j] = self._panel_image(result.image)
                    last_present = max(display.refresh_after(finish), last_present + 1)
                    presents.append((last_present, j))
                    next_app_start = display.vblank_time(last_present)
            if per_display:
                ready = int(np.searchsorted(app_finish, t_display_event, side="right")) - 1
                # before the first application frame is finished the server has nothing to warp
                # (nor, maybe, a tracker sample to warp with): the display stays dark
                if ready >= 0:
                    feed.deliver_until(t_display_event)
                    t_photon = display.photon_time(k, row_estimate)
                    result = self.renderer.render_display_frame(DisplayFrameRequest(k, display.vblank_time(k), t_photon, feed.predict, ready))
                    p = result.pose.position
                    row_estimate = self.layout.display_row_fraction(p)
                    current_image = k
                    shown[k] = _Shown(float(p[0]), row_estimate, feed.newest_sensor_time)
                    panel_images[k] = self._panel_image(result.image)
            else:
                while presents and presents[0][0] <= k:
                    current_image = presents.pop(0)[1]
            content.append(current_image)
            if current_image != NO_IMAGE:
                s = shown[current_image]
                t_photon = display.photon_time(k, s.row_fraction)
                display_log.write([k, display.vblank_time(k), current_image, s.row_fraction, t_photon, s.t_sensor_newest, (t_photon - s.t_sensor_newest) * 1e3, s.x_m])
            next_camera = self._expose_ready_frames(next_camera, display.vblank_time(k + 1), content, panel_images, video)
            if self.board is not None:
                self.board.advance(display.vblank_time(k))
            self._prune(panel_images, content, k)
            if self.progress is not None:
                self.progress(min(display.vblank_time(k) - self.t_begin, self.t_end - self.t_begin), self.t_end - self.t_begin)
            k += 1
        self._expose_ready_frames(next_camera, np.inf, content, panel_images, video)

    def _panel_image(self, image: np.ndarray | None) -> np.ndarray:
        if image is None:
            raise RigError(f"renderer {self.config.renderer!r} returned no image for a frame it was to display")
        _, _, pw, ph = self.layout.panel
        grey = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2GRAY)
        panel = cv2.resize(grey, (pw, ph), interpolation=cv2.INTER_AREA).astype(np.float32)
        camera = self.config.camera
        return camera.display_black_dn + panel * np.float32((camera.display_white_dn - camera.display_black_dn) / 255.0)

    def _expose_ready_frames(
        self,
        next_camera: int,
        t_known_until: float,
        content: list[int],
        panel_images: dict[int, np.ndarray],
        video: VideoFileWriter,
    ) -> int:
        """Expose every camera frame whose exposure ends before the next refresh starts."""
        offsets = self.config.camera.subsample_offsets()
        exposure = self.config.camera.exposure
        while next_camera < len(self.frame_times) and self.frame_times[next_camera] + exposure < t_known_until:
            instants = self.frame_times[next_camera] + offsets
            led = self.layout.led_pixels(self.pendulum.led_position(instants))
            panel = self._panel_light(instants, content, panel_images)
            levels = self.config.board.led_level(instants) if self.config.board is not None else None
            video.write(self.sensor.expose(led, panel, self.layout.panel, levels))
            next_camera += 1
        return next_camera

    def _panel_light(self, instants: np.ndarray, content: list[int], panel_images: dict[int, np.ndarray]) -> np.ndarray:
        """The display panel's light averaged over the given instants, row by row (scan-out)."""
        refresh = self.display.refresh_shown(instants[:, None], self._panel_rows[None, :])
        # Only the last few refreshes can be on screen: look them up without copying all of content.
        first = max(int(refresh.min()), 0)
        recent = np.asarray(content[first:])
        image_ids = np.where(refresh >= 0, recent[np.maximum(refresh, 0) - first], NO_IMAGE)
        _, _, pw, ph = self.layout.panel
        light = np.zeros((ph, pw), dtype=np.float32)
        for image_id in np.unique(image_ids):
            weight = (image_ids == image_id).mean(axis=0).astype(np.float32)
            shown = panel_images[int(image_id)] if image_id != NO_IMAGE else self.config.camera.display_black_dn
            light += weight[:, None] * shown
        return light

    @staticmethod
    def _prune(panel_images: dict[int, np.ndarray], content: list[int], k: int) -> None:
        """Forget images older than anything the last few refreshes show (content only grows)."""
        oldest_needed = min(content[max(0, k - _PRUNE_REFRESHES) :])
        for image_id in [i for i in panel_images if i < oldest_needed]:
            del panel_images[image_id]

    def _truth(self, shown: dict[int, _Shown], content: list[int]) -> dict[str, Any]:
        c = self.config
        rows = [(k, shown[i]) for k, i in enumerate(content) if i != NO_IMAGE]
        refreshes = np.array([k for k, _ in rows])
        switch_times = self.display.vblank_time(refreshes) + self.display.scanout_delay(np.array([s.row_fraction for _, s in rows]))
        x_shown = np.array([s.x_m for _, s in rows])
        newest = np.array([s.t_sensor_newest for _, s in rows])
        camera_span = (0.0, float(self.frame_times[-1] + c.camera.exposure))
        in_span = (switch_times >= camera_span[0]) & (switch_times <= camera_span[1])
        delays_ms = (switch_times - newest)[in_span] * 1e3
        latency_s = effective_latency(
            switch_times,
            x_shown,
            lambda t: self.pendulum.led_position(t)[:, 0],
            camera_span,
            self.pendulum.period_s,
            guess_s=float(delays_ms.mean()) / 1e3,
        )
        return {
            "latency_ms": latency_s * 1e3,
            "latency_definition": "delay tau minimising the mean squared difference between the sphere's x as the display emits it (hold, scan-out row) and the true LED x shifted by tau, over the filmed span",
            "display_frame_delay_ms": {
                "mean": float(delays_ms.mean()),
                "sd": float(delays_ms.std(ddof=1)) if len(delays_ms) > 1 else 0.0,
                "values": [round(float(d), 6) for d in delays_ms],
            },
            "camera_fps": c.camera.fps,
            "frames": len(self.frame_times),
            "period_s": self.pendulum.period_s,
            "display_frame_cost": {"ms": self._warp_ms(), "source": "modelled"} if self.renderer.per_display_frame else None,
            "led_roi": list(self.layout.led_roi),
            "sphere_roi": list(self.layout.sphere_roi),
            "board": self.board.truth() if self.board is not None else None,
            "config": c.to_dict(),
        }


def simulate(
    config: SimulationConfig,
    out_dir: Path,
    progress: Progress | None = None,
    overwrite: bool = False,
) -> SimulationResult:
    """Run the simulated rig and write its video, samples, frame logs and ground truth into out_dir."""
    return Simulation(config, out_dir, progress, overwrite).run()
