"""The simulated world of a run: the pendulum, the bench, and the twins of the devices that live in it.

The rig clock starts `warmup_s` before the camera (at `t_begin`), so the tracker, predictor and
display are in steady state when filming starts at t = 0; the run ends at `t_end`, the film's
length. A simulated run passes the world's `twins()` to the device registry
(`rig.devices.registry.DeviceContext`), whose `sim` spec makes them; the camera films the display
this world made.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Callable

from rig.sim.layout import BenchLayout, make_layout
from rig.sim.board import SimulatedBoard
from rig.sim.camera import SimCamera
from rig.sim.config import SimulationConfig
from rig.sim.display import DisplayConfig, SimDisplay
from rig.sim.flash import FlashingDisplayScene, FlashingLightScene
from rig.sim.pendulum import Pendulum
from rig.sim.scene import FilmedScene
from rig.sim.tracker import SimTracker


class SimulatedWorld:
    """Everything simulated in a run of `config`."""

    def __init__(self, config: SimulationConfig) -> None:
        self.config = config
        self.t_begin = -config.warmup_s
        self.t_end = config.duration_s
        # the truth's latency search (rig.sim.truth) looks up to half a period past either end of the filmed span
        swing_s = config.pendulum.small_angle_period_s
        self.pendulum = Pendulum(
            config.pendulum, t_start=self.t_begin - 1.0, t_end=self.t_end + 1.0 + swing_s, lookback_s=swing_s
        )
        self.layout: BenchLayout = make_layout(self.pendulum, config.camera, config.display, config.layout)
        self._display = SimDisplay(DisplayConfig(**{**asdict(config.display), "t0": self.t_begin}))
        self._camera: SimCamera | None = None

    def tracker(self) -> SimTracker:
        c = self.config
        return SimTracker(self.pendulum, c.tracker, self.t_begin, self.t_end, seed=c.seed)

    def display(self) -> SimDisplay:
        """The world's one display (the camera films it)."""
        return self._display

    def twins(self) -> dict[str, Callable[[], object]]:
        """What makes the `sim` device of each kind."""
        return {"tracker": self.tracker, "display": self.display, "camera": self.camera}

    def camera(self) -> SimCamera:
        """The world's one camera, filming its display's bench, or the calibration target the
        config puts in front of it (`rig.sim.flash`)."""
        if self._camera is None:
            c = self.config
            bench = (self.pendulum, self._display, self.layout, c.camera.display_black_dn, c.camera.display_white_dn, c.board)
            scene: FilmedScene | FlashingLightScene
            if c.flash is None:
                scene = FilmedScene(*bench)
            elif c.flash.source == "light":
                scene = FlashingLightScene(c.flash, self.layout, self._display)
            else:
                scene = FlashingDisplayScene(c.flash, *bench)
            self._camera = SimCamera(c.camera, scene, c.duration_s, seed=c.seed + 1, impairment_seed=c.seed)
        return self._camera

    def board(self, out_dir: Path) -> SimulatedBoard | None:
        """The rig board beside the pendulum, recording into `out_dir`; None without one."""
        if self.config.board is None:
            return None
        return SimulatedBoard(self.config.board, self.pendulum, self.t_begin, self.t_end, out_dir)
