"""The self-test's camera twin: it films a screen rectangle by reading it back from the X server
and adds the emulated tracker's LED, as a camera beside a real pendulum and monitor would see them.

The twin runs in a process of its own, as a camera is a device of its own: the rig's process holds
Python's lock while it renders, which would starve a thread. A frame is taken about every 1 / fps
seconds, on the camera's time slots: the rectangle is read (`XScreen`), the instant it was read is
the middle of the read, and
the LED is drawn where the emulator's pendulum is at that instant plus the display's modelled
scan-out to the sphere's row (found in the image): a real monitor lights that row that much after
the swap the X server shows at once. The sphere and the LED of a frame are thus filmed at the same
instant, however the process is scheduled. Each frame, stamped with that instant and its slot on
the camera's schedule (from which the run's film finds the frames dropped), passes to the rig's
process through a ring of frames in shared memory (`FrameRing`), which `poll()` empties as a real
camera's queue is. The sensor is the simulated one (`rig.sim.camera.CameraSensor`: dark level,
read noise, saturation).

Use a frame rate that shares no small common multiple with the refresh rate: a zero-length
exposure at commensurate rates samples the held image at a few phases only, which biases the
video's latency by a fraction of a refresh.
"""

from __future__ import annotations

import json
import math
import multiprocessing
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import cv2
import numpy as np

from rig.clock import Clock, MonotonicClock
from rig.devices.protocols import CameraFrame, Fault
from rig.sim.layout import BenchLayout
from rig.sim.camera import CameraConfig, CameraSensor
from rig.sim.pendulum import Pendulum, PendulumConfig

SPHERE_LEVEL = 128
"""Grey level above which a screen pixel is the sphere (for finding its row)."""
REPORT_FILE = "camera_twin.json"
STOP_TIMEOUT_S = 20.0
RING_FRAMES = 128
"""Frames the ring holds: `poll` may fall this far behind (about 1.3 s at 97 fps) before frames are lost."""


@dataclass(frozen=True)
class TwinSetup:
    """Everything the twin's process needs (it is started afresh, so all of it is plain data)."""

    config: CameraConfig
    layout: BenchLayout
    pendulum: PendulumConfig
    pendulum_end_s: float
    scanout_s: float
    out_dir: Path
    seed: int


class FrameRing:
    """Frames from one process to another through shared memory: `size` images of `shape`, each
    with its capture instant and its slot's time, and the count written so far. The reader keeps a
    slot's margin from the writer: a reader further behind loses the oldest frames."""

    def __init__(self, context: Any, shape: tuple[int, int], size: int = RING_FRAMES) -> None:
        self.shape, self.size = shape, size
        self.images = context.Array("B", size * shape[0] * shape[1], lock=False)
        self.times = context.Array("d", 2 * size, lock=False)
        self.written = context.Value("q", 0)
        self._read = 0

    def _image(self, i: int) -> np.ndarray:
        return np.frombuffer(self.images, dtype=np.uint8).reshape(self.size, *self.shape)[i % self.size]

    def put(self, grey: np.ndarray, t_capture: float, t_slot: float) -> None:
        i = self.written.value
        self._image(i)[:] = grey
        self.times[2 * (i % self.size) : 2 * (i % self.size) + 2] = [t_capture, t_slot]
        with self.written.get_lock():
            self.written.value = i + 1

    def take(self, exposure_s: float) -> list[CameraFrame]:
        """The frames written since the last call, as camera frames."""
        with self.written.get_lock():
            written = self.written.value
        first, self._read = max(self._read, written - self.size + 1), written
        frames = []
        for i in range(first, written):
            t_capture, t_slot = self.times[2 * (i % self.size) : 2 * (i % self.size) + 2]
            frames.append(CameraFrame(i, t_capture, exposure_s, self._image(i).copy(), t_slot=t_slot))
        return frames


def _row_fraction(grey: np.ndarray) -> float:
    rows = np.flatnonzero((grey > SPHERE_LEVEL).any(axis=1))
    return float((rows.mean() + 0.5) / grey.shape[0]) if rows.size else 0.5


def _film(
    setup: TwinSetup, origin_ns: int, rect: tuple[int, int, int, int], motion_start: Any, stop: Any, ring: FrameRing
) -> None:
    """The twin's process: film into `ring` until `stop` is set, then write REPORT_FILE."""
    from rig.live.selftest.xscreen import XScreen

    clock = MonotonicClock()
    clock.origin_ns = origin_ns
    c, layout = setup.config, setup.layout
    pendulum = Pendulum(setup.pendulum, t_end=setup.pendulum_end_s)
    sensor = CameraSensor(c, setup.seed)
    _, _, pw, ph = layout.panel
    gain = np.float32((c.display_white_dn - c.display_black_dn) / 255.0)
    failure, frames = None, 0
    screen = None
    try:
        screen = XScreen()
        start, slot = clock.now(), 0
        while not stop.is_set():
            # A frame more than half an interval late is dropped, as a camera drops it: frame times
            # stay on the camera's slots, and the run's film fills what was dropped.
            slot = max(slot + 1, math.ceil((clock.now() - start) * c.fps - 0.5))
            clock.wait_until(start + slot / c.fps)
            if math.isnan(motion_start.value):
                continue
            before = clock.now()
            grey = screen.grey(rect)
            t_light = (before + clock.now()) / 2.0 + _row_fraction(grey) * setup.scanout_s
            panel = cv2.resize(grey, (pw, ph), interpolation=cv2.INTER_AREA).astype(np.float32)
            led = layout.led_pixels(pendulum.led_position(np.array([t_light - motion_start.value])).reshape(1, 3))
            ring.put(sensor.expose(led, c.display_black_dn + panel * gain, layout.panel), t_light, start + slot / c.fps)
            frames += 1
    except Exception as error:  # noqa: BLE001 - reported to the run, which ends with it
        failure = f"the camera twin stopped: {type(error).__name__}: {error}"
    finally:
        if screen is not None:
            screen.close()
        report = {"frames": frames, "failure": failure}
        (setup.out_dir / REPORT_FILE).write_text(json.dumps(report) + "\n", encoding="utf-8")


class ScreenCamera:
    """A `Camera` filming `rect()` of the X screen and the pendulum's LED from its own process, which
    starts at the first `poll` (once the run has opened its window); see the module docstring.
    `motion_start()` is the rig time of the pendulum's time 0 (None until the emulator starts)."""

    def __init__(self, setup: TwinSetup, motion_start: Callable[[], float | None], rect: Callable[[], tuple[int, int, int, int]]) -> None:
        self.fps = setup.config.fps
        self.width, self.height = setup.config.width, setup.config.height
        self.setup = setup
        self.result: dict[str, Any] = {}
        self._motion_start = motion_start
        self._rect = rect
        self._context = multiprocessing.get_context("spawn")
        self._start_value = self._context.Value("d", math.nan)
        self._stop = self._context.Event()
        self._ring = FrameRing(self._context, (self.height, self.width))
        self._clock: Clock | None = None
        self._process: Any = None
        self._fault: Fault | None = None

    def connect(self, clock: Clock) -> None:
        self._clock = clock

    def poll(self) -> list[CameraFrame]:
        """The frames the twin took since the last call; tells the twin when the motion started."""
        if self._process is None and self._clock is not None:
            origin_ns = self._clock.origin_ns if isinstance(self._clock, MonotonicClock) else time.monotonic_ns()
            self._process = self._context.Process(
                target=_film, args=(self.setup, origin_ns, self._rect(), self._start_value, self._stop, self._ring),
                name="camera twin", daemon=True,
            )  # fmt: skip
            self._process.start()
        start = self._motion_start()
        if start is not None and math.isnan(self._start_value.value):
            self._start_value.value = start
        if self._process is not None and not self._process.is_alive() and self._fault is None:
            self._fault = Fault(self._clock.now(), "the camera twin's process ended before the run did")
        return self._ring.take(1.0 / self.fps)

    def fault(self) -> Fault | None:
        return self._fault

    def report(self) -> dict[str, Any]:
        return {"camera": "self-test twin (X screen read back, emulated LED)", "fps": self.fps, **self.result}

    def close(self) -> None:
        process, self._process = self._process, None
        if process is None:
            return
        self._stop.set()
        process.join(STOP_TIMEOUT_S)
        if process.is_alive():
            process.terminate()
            process.join()
        report = self.setup.out_dir / REPORT_FILE
        if report.is_file():
            self.result = json.loads(report.read_text(encoding="utf-8"))
