"""How a renderer's work meets the display: its timing policy, what its work costs on the clock,
and the time its poses are predicted for.

A **cost model** says what a piece of the renderer's work costs on the rig clock:

* `ModelledCost(ms)`: a configured number, the same every frame (deterministic, labelled
  "modelled" in the run's logs and truth);
* `MeasuredCost()`: what the renderer reports its work took on this machine ("measured"); on a
  machine with a GPU that is the GPU's time, on software OpenGL the CPU's.

A **timing policy** says when the renderer works and when its images reach the display:

* `OneImagePerAppFrame` (a direct renderer): each application frame is an image. It is handed to
  the display when finished and appears at the first refresh after that (at most one new image a
  refresh); the next application frame starts at the blank that shows it, as a double-buffered
  renderer under vsync does. A frame that takes longer than a refresh leaves the display
  repeating the previous image.
* `CompositeEveryRefresh` (a warp renderer): application frames run back to back at their own
  pace; a server composes images from the newest finished one. It aims each composition at a
  refresh and starts it that refresh's planned cost (plus `SWAP_MARGIN_S`) before its blank. A
  modelled cost is known in advance. For a measured one the server plans, among the last
  PLANNED_COST_WINDOW costs, for the one that minimises an image's expected delay were the next
  cost drawn from them: planning for more adds to every image's delay, and each cost above the
  plan misses its refresh and costs MISS_PENALTY_REFRESHES refreshes. A steady cost is planned
  for in full, a lone stall of the machine is not (it would start the next compositions earlier,
  and so add to their latency). A composition that overruns its blank misses it, and one that
  costs more than a refresh cannot be aimed at every refresh: either way the display repeats the
  last image at the refreshes the server missed. The next composition aims past the refresh the
  last image actually took.

A **photon target** (`PhotonTarget`, in `rig.session.photon_target`) says which instant a display frame's pose is predicted for:
the moment the frame's scan-out reaches the tracked object's row, or the middle of the interval
during which that row then emits it (scan-out plus half the persistence).

The session (`rig.session.session`) is handed one policy and never asks what kind of renderer it
drives; the policy sees the session only as a `Stage` (the display, `show` and `compose`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol, Sequence

import numpy as np

from rig.devices.protocols import Display
from rig.errors import ConfigError
from rig.render.protocol import AppFrameResult, DisplayFrameResult, Renderer
from rig.session.photon_target import PhotonTarget

PLANNED_COST_WINDOW = 60
"""How many of the latest measured server costs the plan for the next one weighs."""
MISS_PENALTY_REFRESHES = 3.0
"""What a missed refresh costs the plan, in refreshes: the one it repeats, and the compositions
after it, which start late behind it and miss too while the machine's stall lasts. On llvmpipe's
measured costs the plan misses 4 to 6 % of refreshes (`rig bench renderers --seed-table`), where
planning for the 90th percentile of the last 20 costs missed about one in ten by construction."""
SWAP_MARGIN_S = 2e-4
"""A composition aims to be ready this long before its blank: a swap at the blank misses it."""


def latency_minimising_cost(costs_s: Sequence[float], miss_s: float) -> float:
    """The cost among `costs_s` to plan the next piece of work for, were its cost drawn from them:
    the one that minimises the expected delay, the planned cost itself plus `miss_s` for each cost
    above it (which would miss its refresh)."""
    ordered = np.sort(np.asarray(costs_s, dtype=np.float64))
    above = np.arange(len(ordered) - 1, -1, -1) / len(ordered)
    return float(ordered[np.argmin(ordered + miss_s * above)])


def _cost_figures(charged_s: Sequence[float]) -> dict[str, Any]:
    costs_ms = np.asarray(charged_s, dtype=np.float64) * 1e3
    if not len(costs_ms):
        return {"frames": 0}
    return {
        "frames": int(len(costs_ms)),
        "median_ms": float(np.median(costs_ms)),
        "p95_ms": float(np.percentile(costs_ms, 95)),
        "max_ms": float(costs_ms.max()),
    }


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
        """What the next piece of work is expected to cost, given what recent work suggests."""
        return self.ms / 1e3

    def describe(self, charged_s: Sequence[float]) -> dict[str, Any]:
        """The cost as the run's truth records it."""
        return {"ms": self.ms, "source": self.source}


@dataclass(frozen=True)
class MeasuredCost:
    """What the work took on this machine."""

    source: ClassVar[str] = "measured"

    def charge(self, measured_s: float) -> float:
        return measured_s

    def expected_s(self, fallback_s: float) -> float:
        return fallback_s

    def describe(self, charged_s: Sequence[float]) -> dict[str, Any]:
        return {"source": self.source, **_cost_figures(charged_s)}


CostModel = ModelledCost | MeasuredCost


def cost_model(ms: float | None) -> CostModel:
    """A modelled cost of `ms`, or the measured one for None."""
    return MeasuredCost() if ms is None else ModelledCost(ms)


class Stage(Protocol):
    """What a timing policy drives (the session): the display, and the two ways an image reaches it."""

    display: Display

    def show(self, image: np.ndarray | None, t_ready: float, image_id: int, position: np.ndarray, cost_s: float,
             cost_source: str) -> int:  # fmt: skip
        """Hand the display an image drawn at `position`, ready at `t_ready` after work that cost
        `cost_s` (`cost_source`: measured or modelled); the refresh it appears at."""
        ...

    def compose(self, k: int, ready: int) -> DisplayFrameResult:
        """The renderer's composed image for refresh k from application frame `ready`, with the
        tracker samples arrived by now."""
        ...


class TimingPolicy(Protocol):
    """When the renderer works and when its images reach the display."""

    def refresh_start(self, display: Display, k: int) -> float:
        """When refresh k's own work starts (application frames starting by then come first);
        no later than the start of any work the policy has planned for a later refresh."""

    def app_frame_done(self, stage: Stage, index: int, result: AppFrameResult, finish: float, cost_s: float,
                       cost_source: str) -> float:  # fmt: skip
        """Take application frame `index`, finished at `finish` after `cost_s` on the clock (as
        `cost_source` says); when the next one starts."""

    def at_refresh(self, stage: Stage, k: int, t_start: float) -> None:
        """Refresh k's own work, at `t_start`."""

    def display_frame_cost(self) -> dict[str, Any] | None:
        """The cost charged per composed image, for the run's truth; None when refreshes cost nothing."""


class OneImagePerAppFrame:
    """A direct renderer's timing; see the module docstring."""

    def refresh_start(self, display: Display, k: int) -> float:
        return display.vblank_time(k)

    def app_frame_done(self, stage: Stage, index: int, result: AppFrameResult, finish: float, cost_s: float,
                       cost_source: str) -> float:  # fmt: skip
        refresh = stage.show(result.image, finish, index, result.pose.position, cost_s, cost_source)
        return stage.display.vblank_time(refresh)

    def at_refresh(self, stage: Stage, k: int, t_start: float) -> None:
        """Nothing: the display repeats the newest image."""

    def display_frame_cost(self) -> dict[str, Any] | None:
        return None


@dataclass
class CompositeEveryRefresh:
    """A warp renderer's timing; see the module docstring."""

    server_cost: CostModel
    _finished: list[float] = field(default_factory=list)
    _charged: list[float] = field(default_factory=list)
    _target: int = 0
    _start: float | None = None
    """When the composition for refresh `_target` starts (None: not planned yet)."""

    def _expected_s(self, display: Display) -> float:
        recent = self._charged[-PLANNED_COST_WINDOW:]
        refresh_s = 1.0 / display.refresh_hz
        if not recent:
            return self.server_cost.expected_s(refresh_s)
        return self.server_cost.expected_s(latency_minimising_cost(recent, MISS_PENALTY_REFRESHES * refresh_s))

    def _plan(self, display: Display, k: int) -> float:
        if self._start is None:
            self._start = display.vblank_time(k) - self._expected_s(display) - SWAP_MARGIN_S
        return self._start

    def refresh_start(self, display: Display, k: int) -> float:
        start = self._plan(display, self._target)
        return start if k == self._target else min(display.vblank_time(k), start)

    def app_frame_done(self, stage: Stage, index: int, result: AppFrameResult, finish: float, cost_s: float,
                       cost_source: str) -> float:  # fmt: skip
        self._finished.append(finish)
        return finish

    def at_refresh(self, stage: Stage, k: int, t_start: float) -> None:
        """Compose for refresh k if the server aimed at it, from the newest application frame
        finished by now; before the first one is, the server has nothing to warp (nor, maybe, a
        tracker sample to warp with): the display stays dark."""
        if k != self._target:
            return
        display = stage.display
        ready = int(np.searchsorted(self._finished, t_start, side="right")) - 1
        if ready < 0:
            self._aim_after(display, k, t_start)
            return
        result = stage.compose(k, ready)
        cost = self.server_cost.charge(result.cost_s)
        self._charged.append(cost)
        finish = t_start + cost
        shown = stage.show(result.image, finish, k, result.pose.position, cost, self.server_cost.source)
        self._aim_after(display, shown, finish)

    def _aim_after(self, display: Display, k: int, free_at: float) -> None:
        """Aim the next composition at the first refresh after k it can be ready for, starting
        once the server is free at `free_at`. k is the refresh the last image appears at, not the
        one it was aimed at: the display shows a new image at most once a refresh, so after an
        overrun the next image aimed at the refresh after k would only queue behind it (and the
        server would stay a refresh late from then on)."""
        lead = self._expected_s(display) + SWAP_MARGIN_S
        target = max(k + 1, display.refresh_after(free_at + lead))
        if display.vblank_time(target - 1) - lead >= free_at and target - 1 > k:
            target -= 1
        self._target = target
        self._start = max(display.vblank_time(target) - lead, free_at)

    def display_frame_cost(self) -> dict[str, Any] | None:
        return self.server_cost.describe(self._charged)


def timing_for(renderer: Renderer, server_cost: CostModel) -> TimingPolicy:
    """The timing policy a renderer's kind asks for; `server_cost` is what a compositing server's
    work costs per image."""
    if renderer.per_display_frame:
        return CompositeEveryRefresh(server_cost)
    return OneImagePerAppFrame()
