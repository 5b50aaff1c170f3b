"""What defines a simulated run: the pendulum, the devices, the renderer and predictor under test,
their costs, and the lab's procedure (a held pendulum released while filming, the rig board)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from rig.errors import ConfigError
from rig.session.timing import DEFAULT_SERVER_MS, PhotonTarget
from rig.sim.bench import DEFAULT_LAYOUT, placement
from rig.sim.board import SimulatedBoardConfig
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.flash import FlashTarget
from rig.sim.pendulum import PendulumConfig
from rig.sim.tracker import TrackerConfig


# (section, field) of settings a run's record leaves out at their defaults (`SimulationConfig.to_dict`).
FILM_DEFAULTS = (
    ("camera", "readout_s"), ("camera", "frame_jitter_s"), ("camera", "container"), ("camera", "codec"), ("", "layout"), ("", "flash"),
)  # fmt: skip


@dataclass(frozen=True)
class SimulationConfig:
    """Everything that defines a simulated run; the same config and seed give the same video
    (with modelled costs: a measured cost is this machine's).

    app_frame_ms, warp_ms: what an application frame and a composed display frame cost on the
    virtual clock, in ms (modelled), or None for what they take on this machine (measured).
    photon_target, persistence: the instant each frame's pose is predicted for
    (`rig.session.PhotonTarget`).
    scene_load: what the load's scene_triangles make (`rig.render.gl.LOAD_SHAPES`; the renderer
    checks it when it opens).
    layout: where the LED and the display sit in the camera's frame (`rig.sim.bench.placement`).
    flash: a calibration target the camera films instead of the bench (`rig.sim.flash`), or None.
    """

    duration_s: float = 10.0
    seed: int = 0
    pendulum: PendulumConfig = field(default_factory=PendulumConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    display: DisplayConfig = field(default_factory=DisplayConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    renderer: str = "direct"
    predictor: str = "default"
    predictor_params: dict[str, Any] = field(default_factory=dict)
    scene_triangles: int = 0
    scene_load: str = "soup"
    app_frame_ms: float | None = 5.0
    warp_ms: float | None = DEFAULT_SERVER_MS
    photon_target: str = "photons"
    persistence: float = 1.0
    warmup_s: float = 0.5
    board: SimulatedBoardConfig | None = None
    layout: str = DEFAULT_LAYOUT
    flash: FlashTarget | None = None

    def __post_init__(self) -> None:
        placement(self.layout)
        if not (np.isfinite(self.duration_s) and 0.5 <= self.duration_s <= 3600.0):
            raise ConfigError(f"duration must be 0.5-3600 s, got {self.duration_s}")
        if self.scene_triangles < 0:
            raise ConfigError(f"scene triangles must be >= 0, got {self.scene_triangles}")
        if self.app_frame_ms is not None and not (np.isfinite(self.app_frame_ms) and self.app_frame_ms > 0):
            raise ConfigError(f"application frame cost must be a positive number of ms, got {self.app_frame_ms}")
        if self.warp_ms is not None and not (np.isfinite(self.warp_ms) and self.warp_ms > 0):
            raise ConfigError(f"warp cost must be a positive number of ms, got {self.warp_ms}")
        PhotonTarget(self.photon_target, self.persistence)
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
        return getattr(self, name) == getattr(SimulationConfig, name)
