"""The seams between a run and the world: a tracker, a display, a camera, and instruments beside them.

A session (`rig.session`) sees devices only through these protocols, so a simulated twin
(`rig.sim`), a real device and a third party's plug-in are interchangeable. Every device follows
the same life cycle: its constructor stores settings and opens nothing; `connect(clock)` opens it
and puts its timestamps on the run's clock (`rig.clock`); `close()` releases it and may be called
more than once. No method blocks on I/O except the ones that say they wait. Each device says what
it did in `report()` (JSON-ready: counts, drops, failures; the run's summary holds it), and a
source whose data may stop (a tracker, a camera) says so in `fault()`, so a live run can end with
a reason rather than wait.

Times are seconds on the rig clock. Images are numpy arrays: a display takes RGB uint8
(height, width, 3), row 0 at the top (the row scanned out first); a camera gives grey uint8
(height, width).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from predictors import PoseSample
from rig.clock import Clock

NO_IMAGE = -1
"""The image id of a refresh that shows nothing yet (a dark display)."""


@dataclass(frozen=True)
class Fault:
    """A device that has stopped delivering: since when (rig clock) and why, in a sentence."""

    since: float
    reason: str


@runtime_checkable
class TrackerSource(Protocol):
    """Pose samples, each stamped with the sensor's time and the host's arrival time."""

    def connect(self, clock: Clock) -> None: ...

    def poll(self) -> list[PoseSample]:
        """Every sample that has arrived by now and was not returned before, in arrival order."""
        ...

    def wait(self, timeout_s: float) -> list[PoseSample]:
        """As `poll`, but first wait (on the clock) until a sample has arrived, at most `timeout_s`;
        empty if none came."""
        ...

    def fault(self) -> Fault | None:
        """Why no sample comes any more, and since when; None while samples come (a source that
        reconnects on its own clears it once it has)."""
        ...

    def report(self) -> dict[str, Any]:
        """What the source delivered and lost so far (counters, link events), JSON-ready."""
        ...

    def close(self) -> None: ...


@runtime_checkable
class Display(Protocol):
    """Shows images at its refreshes and says when each refresh's light leaves which row.

    Refresh k starts at `vblank_time(k)`; rows are lit top to bottom from there. An image handed
    over with `present` appears at a refresh after it was ready (at most one new image a refresh)
    and stays until the next one (sample-and-hold).
    """

    width: int
    height: int
    refresh_hz: float
    """The refresh rate: nominal until connected, then what the display measured where it measures
    it (a window); read it after `connect`."""

    def connect(self, clock: Clock) -> None: ...

    def vblank_time(self, k: int) -> float:
        """When refresh k starts."""
        ...

    def refresh_after(self, t: float) -> int:
        """The first refresh that starts strictly after `t`."""
        ...

    def photon_time(self, k: int, row_fraction: float) -> float:
        """When refresh k's light leaves the row at `row_fraction` (0 top, 1 bottom)."""
        ...

    def present(self, image: np.ndarray, t_ready: float, image_id: int) -> int:
        """Hand over `image`, finished at `t_ready`, under `image_id`; the refresh it appears at."""
        ...

    def shown(self, k: int) -> int:
        """The id of the image refresh k shows (NO_IMAGE: none yet); asked for k = 0, 1, 2, ... in
        turn, as the run reaches each refresh."""
        ...

    def report(self) -> dict[str, Any]:
        """How the refreshes were timed and how many images were late, JSON-ready."""
        ...

    def close(self) -> None: ...


@dataclass(frozen=True, eq=False)
class CameraFrame:
    """One camera frame: its index, when its exposure started (or, for a camera that does not say,
    when it was captured) and how long it lasted, its image; its readout: a rolling shutter exposes
    row y of the image's H rows from t_start + (y / H) readout_s (0: a global shutter, or a camera
    that does not know its readout); where the camera keeps a schedule, the frame's place on it (the
    run's film finds dropped frames from it), and the capture backend's own timestamp where it gives
    one."""

    index: int
    t_start: float
    exposure_s: float
    image: np.ndarray
    readout_s: float = 0.0
    t_slot: float | None = None
    t_backend_ms: float | None = None

    def row_start(self, row: float | np.ndarray) -> float | np.ndarray:
        """When row `row` (0 at the top) of this frame started exposing."""
        return self.t_start + np.asarray(row, dtype=np.float64) / self.image.shape[0] * self.readout_s


@runtime_checkable
class Camera(Protocol):
    """Frames of the bench, each with its exposure on the rig clock. `fps`, `width` and `height`
    are what the camera delivers once connected (a real camera says then what it took)."""

    fps: float
    width: int
    height: int

    def connect(self, clock: Clock) -> None: ...

    def poll(self) -> list[CameraFrame]:
        """Every frame complete by now and not returned before, in order."""
        ...

    def fault(self) -> Fault | None:
        """Why no frame comes any more, and since when; None while frames come."""
        ...

    def report(self) -> dict[str, Any]:
        """What the camera was asked for, what it gave and how it ended, JSON-ready."""
        ...

    def close(self) -> None: ...


@runtime_checkable
class Instrument(Protocol):
    """Something that records beside a run on its own (the rig board): the session polls it as the
    run goes, so it records up to the present; `finish` completes its record when the run ends
    normally, `close` follows on any exit."""

    def connect(self, clock: Clock) -> None: ...

    def poll(self) -> None: ...

    def finish(self) -> None: ...

    def close(self) -> None: ...
