"""How a renderer's work meets the display: its timing policy, and what its work costs on the clock.

A **cost model** says what a piece of the renderer's work costs on the rig clock:

* `ModelledCost(ms)`: a configured number, the same every frame (deterministic, labelled
  "modelled" in the run's logs and truth);
* `MeasuredCost()`: what the renderer reports its work took on this machine ("measured").

A **timing policy** says when the renderer works and when its images reach the display:

* `OneImagePerAppFrame` (a direct renderer): each application frame is an image. It is handed to
  the display when finished and appears at the first refresh after that (at most one new image a
  refresh); the next application frame starts at the blank that shows it, as a double-buffered
  renderer under vsync does.
* `CompositeEveryRefresh` (a warp renderer): application frames run back to back at their own
  pace; at every refresh the renderer composes a new image from the newest finished one, starting
  the server's cost before the blank so that the image is ready for it.

The session (`rig.session.session`) is handed one of each and never asks what kind of renderer it
drives.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np

from rig.errors import ConfigError
from rig.render.protocol import AppFrameResult, DisplayFrameRequest, Renderer

if TYPE_CHECKING:
    from rig.devices.protocols import Display
    from rig.session.session import Session


@dataclass(frozen=True)
class ModelledCost:
    """A configured cost (ms), charged whatever the work took."""

    ms: float
    source: ClassVar[str] = "modelled"

    def __post_init__(self) -> None:
        if not (np.isfinite(self.ms) and self.ms > 0):
            raise ConfigError(f"a modelled cost must be a positive number of ms, got {self.ms!r}")

    def charge(self, measured_s: float) -> float:
        """The seconds the clock charges for work that took `measured_s`."""
        return self.ms / 1e3

    def expected_s(self, fallback_s: float) -> float:
        """What the next piece of work is expected to cost before any has been done."""
        return self.ms / 1e3


@dataclass(frozen=True)
class MeasuredCost:
    """What the work took on this machine."""

    source: ClassVar[str] = "measured"

    def charge(self, measured_s: float) -> float:
        return measured_s

    def expected_s(self, fallback_s: float) -> float:
        return fallback_s


CostModel = ModelledCost | MeasuredCost


def cost_model(ms: float | None) -> CostModel:
    """A modelled cost of `ms`, or the measured one for None."""
    return MeasuredCost() if ms is None else ModelledCost(ms)


class TimingPolicy(Protocol):
    """When the renderer works and when its images reach the display."""

    def refresh_start(self, display: Display, k: int) -> float:
        """When refresh k's own work starts (application frames starting by then come first)."""

    def app_frame_done(self, session: Session, index: int, result: AppFrameResult, finish: float) -> float:
        """Take application frame `index`, finished at `finish`; when the next one starts."""

    def at_refresh(self, session: Session, k: int, t_start: float) -> None:
        """Refresh k's own work, at `t_start`."""

    def display_frame_cost(self) -> dict[str, Any] | None:
        """The cost charged per refresh, for the run's truth; None when refreshes cost nothing."""


class OneImagePerAppFrame:
    """A direct renderer's timing; see the module docstring."""

    def refresh_start(self, display: Display, k: int) -> float:
        return display.vblank_time(k)

    def app_frame_done(self, session: Session, index: int, result: AppFrameResult, finish: float) -> float:
        refresh = session.show(result.image, finish, index, result.pose.position)
        return session.display.vblank_time(refresh)

    def at_refresh(self, session: Session, k: int, t_start: float) -> None:
        """Nothing: the display repeats the newest image."""

    def display_frame_cost(self) -> dict[str, Any] | None:
        return None


@dataclass
class CompositeEveryRefresh:
    """A warp renderer's timing; see the module docstring. The server's cost is modelled: it must be
    known before the blank to start in time."""

    server_cost: ModelledCost
    _finished: list[float] = field(default_factory=list)

    def refresh_start(self, display: Display, k: int) -> float:
        return display.vblank_time(k) - self.server_cost.ms / 1e3

    def app_frame_done(self, session: Session, index: int, result: AppFrameResult, finish: float) -> float:
        self._finished.append(finish)
        return finish

    def at_refresh(self, session: Session, k: int, t_start: float) -> None:
        """Compose from the newest application frame finished by now; before the first one is, the
        server has nothing to warp (nor, maybe, a tracker sample to warp with): the display stays dark."""
        ready = int(np.searchsorted(self._finished, t_start, side="right")) - 1
        if ready < 0:
            return
        session.feed.deliver()
        display = session.display
        t_photon = display.photon_time(k, session.row_estimate)
        result = session.renderer.render_display_frame(
            DisplayFrameRequest(k, display.vblank_time(k), t_photon, session.feed.predict, ready)
        )
        session.show(result.image, t_start, k, result.pose.position)

    def display_frame_cost(self) -> dict[str, Any] | None:
        return {"ms": self.server_cost.ms, "source": self.server_cost.source}


DEFAULT_SERVER_MS = 2.0
"""Modelled server cost per refresh of a renderer that composes at every refresh, where a run gives
none: a GPU's point warp of a display-sized image, well inside a refresh. Software OpenGL takes
longer; `rig bench renderers` reports the real cost beside the modelled one."""


def timing_for(renderer: Renderer, server_ms: float | None) -> TimingPolicy:
    """The timing policy a renderer's kind asks for; `server_ms` models a compositing server's cost
    per refresh (DEFAULT_SERVER_MS when None)."""
    if renderer.per_display_frame:
        return CompositeEveryRefresh(ModelledCost(server_ms if server_ms is not None else DEFAULT_SERVER_MS))
    return OneImagePerAppFrame()
