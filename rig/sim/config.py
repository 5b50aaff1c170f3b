"""What defines a simulated run: the pendulum, the devices, the renderer and predictor under test,
their costs, and the lab's procedure (a held pendulum released while filming, the rig board)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from declared import Flag, Range, check, like, setting
from rig.errors import ConfigError
from rig.session.photon_target import DEFAULT_SERVER_MS, PhotonTarget
from rig.sim.board_config import SimulatedBoardConfig
from rig.sim.camera_config import CameraConfig
from rig.sim.display_config import DisplayConfig
from rig.sim.flash_target import FlashTarget
from rig.sim.pendulum_config import PendulumConfig
from rig.sim.placement import DEFAULT_LAYOUT, LAYOUT_HELP, placement
from rig.sim.tracker_config import TrackerConfig

MEASURED = "measured"
"""A cost given as this (on the command line, in a spec) is what this machine's GL takes."""
PIXEL_INSTANTS_PER_S = 1e9
"""Sensor pixels the simulated camera films per second, one exposure instant each: a generous rate
(this machine films about 8e8)."""
TRIANGLES_PER_S = 1e9
"""Load triangles the renderer draws per second: a generous rate for a GPU."""
MAX_HOURS = 24.0
"""The longest simulation the rig starts: longer is a mistake in the settings, not a lab's run."""
LOAD_SHAPES = ("soup", "meshes")
"""What the load's triangles make (`rig.render.gl.load_triangles`): a soup of small random
triangles (the stress case: every visible fragment a few pixels wide) or a few solid objects
tessellated into them (what a real scene's triangles are)."""
# (section, field) of settings a run's record leaves out at their defaults (`SimulationConfig.to_dict`).
FILM_DEFAULTS = (
    ("camera", "readout_s"), ("camera", "frame_jitter_s"), ("camera", "container"), ("camera", "codec"), ("", "layout"), ("", "flash"),
)  # fmt: skip


def _layout_problem(layout: str) -> str | None:
    """A layout named or spelt out, the LED's swing and the panel apart inside the frame (`placement`)."""
    try:
        placement(layout)
    except ConfigError as error:
        return str(error)
    return None


@dataclass(frozen=True)
class SimulationConfig:
    """Everything that defines a simulated run; the same config and seed give the same video
    (with modelled costs: a measured cost is this machine's).

    Each setting is declared once on its field (`declared.setting`: unit, range, help, the command
    line's option), nested configs' in their own modules: `rig simulate`'s options, a sweep's keys
    and the docs' table are made from them. app_frame_ms, warp_ms: what an application frame and a
    composed display frame cost on the virtual clock, in ms (modelled), or None (MEASURED) for what
    they take on this machine. photon_target, persistence: `rig.session.PhotonTarget`'s. scene_load:
    the renderer checks it when it opens. layout: where the LED and the display sit in the camera's
    frame (`rig.sim.layout.placement`). The pendulum's release and the board's blink must fall within
    the film. flash: a calibration target the camera films instead of the bench (`rig.sim.flash`), or
    None.
    """

    duration_s: float = setting(
        10.0, "seconds", "length of the film (a lab films seconds to minutes; an hour at most)", Range(0.5, 3600.0, True, True),
        flag="--duration",
    )  # fmt: skip
    seed: int = setting(0, "", "random seed; the same seed gives the same video", Range(0.0, 1e9, True, True), flag="--seed")
    pendulum: PendulumConfig = field(default_factory=PendulumConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    display: DisplayConfig = field(default_factory=DisplayConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    renderer: str = setting(
        "direct", "", "renderer under test (listed below) and its options, e.g. warp:views=2,recon=grid,holes=1",
        flag=Flag("--renderer", metavar="NAME[:key=value,...]"),
    )  # fmt: skip
    predictor: str = setting("default", "", "pose predictor (listed below); on the command line with its parameters, --predictor")
    predictor_params: dict[str, Any] = field(default_factory=dict)
    scene_triangles: int = setting(
        0, "triangles", "load geometry drawn behind the sphere (a heavy VR scene draws a few million a frame; 100 "
        "million is past any GPU's frame budget)", Range(0.0, 1e8, True, True), flag="--scene-triangles",
    )  # fmt: skip
    scene_load: str = setting("soup", "", "what the load's triangles make (rig.render.gl.LOAD_SHAPES)")
    app_frame_ms: float | None = setting(
        5.0, "ms", "modelled application frame cost, or 'measured' for the real GL time (at most a second: slower is no "
        "interactive application)", Range(0.0, 1000.0, includes_high=True), none=MEASURED,
        flag="--app-frame-ms",
    )  # fmt: skip
    warp_ms: float | None = setting(
        DEFAULT_SERVER_MS, "ms", "modelled cost of each image a compositing (warp) renderer composes, or 'measured' for "
        "the real GL time: a composition that takes longer than a refresh misses it (at most a second, a refresh of the "
        "slowest display)", Range(0.0, 1000.0, includes_high=True), none=MEASURED, flag="--warp-ms",
    )  # fmt: skip
    photon_target: str = like(PhotonTarget, "mode", flag=Flag("--predict-to"))
    persistence: float = like(PhotonTarget, "persistence", flag=Flag("--persistence"))
    warmup_s: float = setting(0.5, "seconds", "the rig clock's start before the camera's, so that the rig is in its steady state",
        Range(0.0, 60.0, True, True),
    )  # fmt: skip
    board: SimulatedBoardConfig | None = None
    layout: str = setting(
        DEFAULT_LAYOUT, "", f"where the LED and the display sit in the frame: {LAYOUT_HELP}", rule=_layout_problem,
        flag=Flag("--layout", metavar="LAYOUT"),
    )  # fmt: skip
    flash: FlashTarget | None = None

    def __post_init__(self) -> None:
        check(self, ConfigError)
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
        hours = self.estimated_hours()
        if hours > MAX_HOURS:
            raise ConfigError(
                f"this run would take about {hours:.3g} hours ({self.duration_s:g} s filmed at {self.camera.fps:g} fps, "
                f"{self.camera.width}x{self.camera.height} pixels, {self.camera.subsamples} instants an exposure, "
                f"{self.scene_triangles} load triangles), more than the {MAX_HOURS:g} hours the rig starts: film "
                "shorter, slower, smaller or with fewer triangles"
            )

    def estimated_hours(self) -> float:
        """Hours the run takes at generous rates (PIXEL_INSTANTS_PER_S, TRIANGLES_PER_S): its film's
        pixel-instants and its scene's triangles, drawn at most once a refresh and at least once an
        application frame. Every setting may be within its range while their product (a long film at
        a high rate, a heavy scene drawn many times) is days of work: such a run is refused."""
        camera = self.camera
        filming_s = self.duration_s * camera.fps * camera.width * camera.height * camera.subsamples / PIXEL_INSTANTS_PER_S
        frame_s = (self.app_frame_ms or 0.0) / 1e3
        frames_per_s = self.display.refresh_hz if frame_s == 0.0 else min(self.display.refresh_hz, 1.0 / frame_s)
        drawing_s = (self.duration_s + self.warmup_s) * frames_per_s * self.scene_triangles / TRIANGLES_PER_S
        return (filming_s + drawing_s) / 3600.0

    def to_dict(self) -> dict[str, Any]:
        """The config as plain values; the camera's rolling shutter, frame timing and film file and
        the bench's layout are left out where they are the defaults (`FILM_DEFAULTS`), so that a
        global-shutter run's record is what it was before cameras had them."""
        record = asdict(self)
        for section, name in FILM_DEFAULTS:
            if self._film_default(section, name):
                del (record[section] if section else record)[name]
        return record

    def films_by_default(self) -> bool:
        """Whether the camera has a global shutter, a constant rate and an MJPEG AVI, on the default layout."""
        return all(self._film_default(section, name) for section, name in FILM_DEFAULTS)

    def _film_default(self, section: str, name: str) -> bool:
        if section == "camera":
            return getattr(self.camera, name) == getattr(CameraConfig(), name)
        return getattr(self, name) == getattr(SimulationConfig(), name)
