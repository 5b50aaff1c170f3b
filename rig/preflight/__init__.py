"""`rig check`: a pre-flight check of the devices a live run would use, in a few seconds.

The tracker and the camera are listened to on threads of their own for LISTEN_S after each opens,
while the window is opened and images presented on this one, as a run does (`display.py`); then the
disk is checked for the film. Each check is a row (`rows.CheckRow`): pass, warn or fail, what was
measured, and what to fix. A device that will not open is a failed row, not an error: the others are
still checked. A malformed spec is the user's error (ConfigError), raised before anything opens.
"""

from __future__ import annotations

import threading
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from rig.clock import MonotonicClock
from rig.devices.window import FrameClock
from rig.preflight.camera import CameraProbe
from rig.preflight.display import check_display
from rig.preflight.disk import check_disk
from rig.preflight.rows import CheckRow, worst
from rig.preflight.tracker import TrackerProbe

LISTEN_S = 3.0
"""How long the tracker and the camera are listened to, each from when it opens."""


@dataclass(frozen=True)
class CheckPlan:
    """The devices a run would use (None: the run has none of that kind; `display` None: an external
    renderer draws), the planned run's duration, and an existing folder on the disk it is written to."""

    tracker: str | None
    camera: str | None
    display: str | None
    duration_s: float
    disk_folder: Path
    accept_camera_settings: bool = False


@dataclass(frozen=True)
class CheckReport:
    rows: list[CheckRow]
    seconds: float
    """How long the check took, start to end."""

    @property
    def status(self) -> str:
        return worst(self.rows)

    def to_dict(self) -> dict[str, Any]:
        return {"status": self.status, "seconds": self.seconds, "checks": [asdict(row) for row in self.rows]}


def run_checks(plan: CheckPlan, *, frame_clock: FrameClock | None = None, clock: MonotonicClock | None = None) -> CheckReport:
    """Check every device of `plan` (see the module docstring); `frame_clock` paces the window instead
    of the monitor (under a virtual X server)."""
    clock = clock or MonotonicClock()
    started = clock.now()
    tracker = TrackerProbe(plan.tracker) if plan.tracker else None
    camera = CameraProbe(plan.camera.removeprefix("camera:"), plan.accept_camera_settings) if plan.camera else None
    listening = [
        threading.Thread(
            target=probe.run, args=(clock, LISTEN_S), name=f"rig check {type(probe).__name__}", daemon=True
        )
        for probe in (tracker, camera)
        if probe is not None
    ]
    for thread in listening:
        thread.start()
    try:
        rows = check_display(plan.display, clock, frame_clock) if plan.display is not None else []
    finally:
        for thread in listening:
            thread.join()
    if tracker is not None:
        rows += tracker.rows(LISTEN_S)
    if camera is not None:
        rows += camera.rows(LISTEN_S)
    rows.append(check_disk(plan.disk_folder, camera.fps if camera else None, camera.frame_bytes() if camera else None, plan.duration_s))
    return CheckReport(rows, clock.now() - started)
