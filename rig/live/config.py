"""What a live run is told (`LiveConfig`), declared without the run's libraries: `rig measure`'s
options are made from it, and `rig.live.run` runs it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from declared import Flag, Range, check, like, setting
from rig.devices.window_settings import WindowSettings
from rig.errors import ConfigError
from rig.lsl.streams import LSL, StreamNames
from rig.session.photon_target import PhotonTarget

EXTERNAL = "external"
RENDERER, RUN = "renderer", "run"
"""The groups of a live run's options, the streams' (`rig.lsl.streams.LSL`) after them: `rig measure`
lists its own options between them (--duration too: the self-test's default is shorter)."""


@dataclass(frozen=True)
class LiveConfig:
    """One live run: which tracker, renderer (EXTERNAL: another program over LSL) and predictor, how
    long, and how the display's frames are aimed."""

    tracker: str
    renderer: str = setting("warp", "", "the rig's renderer (listed below), with options as warp:OPTIONS",
                            flag=Flag("--renderer", metavar="NAME", group=RENDERER))  # fmt: skip
    predictor: str = "default"
    predictor_params: dict[str, Any] = field(default_factory=dict)
    duration_s: float = setting(60.0, "seconds", "how long the run lasts, at most a day",
                                Range(0.0, 86400.0, includes_high=True))  # fmt: skip
    window: WindowSettings = WindowSettings()
    scanout_fraction: float = 1.0
    until_still: bool = setting(False, "", "end sooner once the pendulum has stopped swinging",
                                flag=Flag("--until-still", group=RUN))  # fmt: skip
    photon_target: str = like(
        PhotonTarget, "mode", flag=Flag("--photon-target", help="what each frame's pose is predicted for", group=RUN)
    )  # fmt: skip
    mirror: bool = setting(False, "", "mirror the screen's x (when the camera sees the sphere move against the LED)",
                           flag=Flag("--mirror", group=RUN))  # fmt: skip
    persistence: float = like(PhotonTarget, "persistence")
    scene_triangles: int = 0
    streams: StreamNames | None = StreamNames()

    def __post_init__(self) -> None:
        check(self, ConfigError)
        if self.renderer == EXTERNAL and self.streams is None:
            raise ConfigError("an external renderer is reached through LSL: the run needs its streams")
