"""`camera:SOURCE`: a camera read with OpenCV (`rig.devices.protocols.Camera`).

    camera:0                                  the first video device
    camera:0?fps=240&size=640x480&exposure=-7&fourcc=MJPG
    camera:recording.avi                      a file, played at its own frame rate
    camera:tcp://192.168.1.20:8554            a network stream (anything OpenCV's FFmpeg opens)

The settings a run asks for (frame rate, resolution, exposure, pixel format) are set when the camera
opens and read back; a setting the camera did not take is reported with what it gave instead and,
unless `accept_refused` is set, refuses the run (RigError) rather than measuring with a camera that
silently ignored it. Exposure is in the backend's own units (V4L2: 100 us steps; auto exposure is
turned off when one is given). A file's rate and size are its own; it plays at its rate, frame i
stamped at the start plus i intervals.

A capture thread reads frames as they come, stamps each on the rig clock the moment it is grabbed
(keeping the backend's timestamp beside it) and queues it for `poll()`, which hands over every frame
captured since the last call (the run's film writes them, `rig.session.run_record.FilmRecord`). A
camera that stops delivering (unplugged, the stream closed) ends the capture and says so in
`fault()`; a file that has played to its end is `finished`.
"""

from __future__ import annotations

import threading
from collections import deque
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import parse_qsl

import cv2

from analysis.video.native_path import native_path
from rig.clock import Clock
from rig.devices.protocols import CameraFrame, Fault
from rig.errors import ConfigError, RigError

FPS_TOLERANCE = 0.01
V4L2_MANUAL_EXPOSURE = 1
OPEN_TIMEOUT_MS = 10000
READ_TIMEOUT_MS = 2000
"""A camera silent this long is taken as gone."""


@dataclass(frozen=True)
class CameraSettings:
    """What a run asks of the camera; None leaves the camera's own."""

    fps: float | None = None
    size: tuple[int, int] | None = None
    exposure: float | None = None
    fourcc: str | None = None

    def requested(self) -> dict[str, Any]:
        return {key: value for key, value in asdict(self).items() if value is not None}


@dataclass(frozen=True)
class CameraSource:
    """Where frames come from: a device index, a file or a stream URL."""

    kind: str
    address: str

    @property
    def target(self) -> int | str:
        return int(self.address) if self.kind == "device" else native_path(self.address)


def parse_camera_address(address: str) -> tuple[CameraSource, CameraSettings]:
    """(source, settings) from `SOURCE[?fps=F&size=WxH&exposure=E&fourcc=XXXX]`; other query options
    stay with a stream URL."""
    source, _, query = address.partition("?")
    options = dict(parse_qsl(query, keep_blank_values=True))
    try:
        fps = float(options.pop("fps")) if "fps" in options else None
        size = tuple(int(v) for v in options.pop("size").lower().split("x")) if "size" in options else None
        exposure = float(options.pop("exposure")) if "exposure" in options else None
    except ValueError:
        raise ConfigError(f"camera:{address}: fps and exposure are numbers and size is WIDTHxHEIGHT") from None
    fourcc = options.pop("fourcc", None)
    if size is not None and len(size) != 2:
        raise ConfigError(f"camera:{address}: size is WIDTHxHEIGHT, such as 640x480")
    if fourcc is not None and len(fourcc) != 4:
        raise ConfigError(f"camera:{address}: fourcc is four characters, such as MJPG")
    if options:
        source = f"{source}?{'&'.join(f'{k}={v}' for k, v in options.items())}"
    if not source:
        raise ConfigError("a camera needs a source: camera:0 (a device index), camera:FILE or camera:URL")
    kind = "device" if source.isdigit() else "stream" if "://" in source else "file"
    return CameraSource(kind, source), CameraSettings(fps, size, exposure, fourcc)  # type: ignore[arg-type]


def _fourcc_text(value: float) -> str:
    code = int(value)
    return "".join(chr((code >> 8 * i) & 0xFF) for i in range(4)) if code > 0 else ""


@dataclass
class SettingsCheck:
    """What was asked, what the camera reports after being asked, and what it refused."""

    requested: dict[str, Any]
    reported: dict[str, Any]
    refused: list[str] = field(default_factory=list)


def apply_settings(capture: Any, settings: CameraSettings, kind: str) -> SettingsCheck:
    """Set `settings` on an opened cv2.VideoCapture and read every one back."""
    requested = settings.requested()
    if kind == "file" and requested:
        raise ConfigError(f"a file's frame rate, size and format are its own; drop {', '.join(requested)} for a file camera")
    if settings.fourcc is not None:
        capture.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter_fourcc(*settings.fourcc))
    if settings.size is not None:
        capture.set(cv2.CAP_PROP_FRAME_WIDTH, settings.size[0])
        capture.set(cv2.CAP_PROP_FRAME_HEIGHT, settings.size[1])
    if settings.fps is not None:
        capture.set(cv2.CAP_PROP_FPS, settings.fps)
    if settings.exposure is not None:
        capture.set(cv2.CAP_PROP_AUTO_EXPOSURE, V4L2_MANUAL_EXPOSURE)
        capture.set(cv2.CAP_PROP_EXPOSURE, settings.exposure)
    reported = {
        "fps": float(capture.get(cv2.CAP_PROP_FPS)),
        "size": (int(capture.get(cv2.CAP_PROP_FRAME_WIDTH)), int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))),
        "exposure": float(capture.get(cv2.CAP_PROP_EXPOSURE)),
        "fourcc": _fourcc_text(capture.get(cv2.CAP_PROP_FOURCC)),
    }
    check = SettingsCheck(requested, reported)
    for key, wanted in requested.items():
        got = reported[key]
        if key == "fps":
            taken = got > 0 and abs(got - wanted) <= FPS_TOLERANCE * wanted
        elif key == "exposure":
            taken = abs(got - wanted) <= 1e-6 * max(1.0, abs(wanted))
        else:
            taken = got == wanted
        if not taken:
            check.refused.append(f"{key} {wanted} (the camera reports {got})")
    return check


class OpenCvCamera:
    """A camera read through OpenCV on its own thread; see the module docstring."""

    def __init__(self, source: CameraSource, settings: CameraSettings, *, accept_refused: bool = False) -> None:
        self.source = source
        self.settings = settings
        self.spec = f"camera:{source.address}"
        self.fps = settings.fps or 0.0
        self.width, self.height = settings.size or (0, 0)
        self.check: SettingsCheck | None = None
        self.captured = 0
        self.finished = False
        self._fault: Fault | None = None
        self._accept_refused = accept_refused
        self._capture: Any = None
        self._clock: Clock | None = None
        self._queue: deque[CameraFrame] = deque()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def connect(self, clock: Clock) -> None:
        """Open the camera, apply and check the settings, start capturing (RigError if it cannot)."""
        self._clock = clock
        if self.source.kind == "file" and not Path(self.source.address).is_file():
            raise RigError(f"no video file {self.source.address} for camera:{self.source.address}")
        backend = cv2.CAP_ANY if self.source.kind == "device" else cv2.CAP_FFMPEG
        timeouts = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, OPEN_TIMEOUT_MS, cv2.CAP_PROP_READ_TIMEOUT_MSEC, READ_TIMEOUT_MS]
        quiet = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)  # failures are ours to explain
        try:
            capture = cv2.VideoCapture(self.source.target, backend, timeouts)
        finally:
            cv2.utils.logging.setLogLevel(quiet)
        if not capture.isOpened():
            capture.release()
            what = {"device": "no camera answers at index", "stream": "cannot open the stream", "file": "cannot read the video"}
            raise RigError(f"{what[self.source.kind]} {self.source.address}; `rig devices` lists the cameras it sees")
        try:
            self.check = apply_settings(capture, self.settings, self.source.kind)
        except BaseException:
            capture.release()
            raise
        if self.check.refused and not self._accept_refused:
            capture.release()
            raise RigError(
                f"camera {self.source.address} refused {'; '.join(self.check.refused)}; choose settings it offers, "
                "or pass --accept-camera-settings to measure with what it gives"
            )
        self.fps = self.check.reported["fps"] or self.settings.fps or 30.0
        self.width, self.height = self.check.reported["size"]
        self._capture = capture
        self._thread = threading.Thread(target=self._capture_loop, name=f"camera {self.source.address}", daemon=True)
        self._thread.start()

    def _capture_loop(self) -> None:
        capture, clock = self._capture, self._clock
        paced_start: float | None = None
        while not self._stop.is_set():
            index = self.captured
            if self.source.kind == "file":
                paced_start = clock.now() if paced_start is None else paced_start
                clock.wait_until(paced_start + index / self.fps)
            if not capture.grab():
                if self.source.kind == "file":
                    self.finished = True
                else:
                    gone = f"camera {self.source.address} stopped delivering frames (unplugged, or the stream ended)"
                    self._fault = Fault(clock.now(), gone)
                return
            t_capture = paced_start + index / self.fps if paced_start is not None else clock.now()
            backend_ms = float(capture.get(cv2.CAP_PROP_POS_MSEC))
            ok, image = capture.retrieve()
            if not ok:
                self._fault = Fault(t_capture, f"camera {self.source.address} delivered a frame it could not decode")
                return
            grey = image if image.ndim == 2 else cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
            frame = CameraFrame(index, t_capture, 1.0 / self.fps, grey, t_backend_ms=backend_ms if backend_ms > 0 or index == 0 else None)
            with self._lock:
                self._queue.append(frame)
            self.captured += 1

    def poll(self) -> list[CameraFrame]:
        """Every frame captured since the last call."""
        with self._lock:
            frames = list(self._queue)
            self._queue.clear()
        return frames

    def fault(self) -> Fault | None:
        return self._fault

    def report(self) -> dict[str, Any]:
        return {
            "camera": self.spec,
            "source": self.source.kind,
            "requested": self.check.requested if self.check else self.settings.requested(),
            "reported": self.check.reported if self.check else None,
            "refused": self.check.refused if self.check else [],
            "captured": self.captured,
            "failure": f"{self._fault.reason} at {self._fault.since:.3f} s" if self._fault else None,
        }

    def close(self) -> None:
        """Stop capturing and release the camera; safe to repeat."""
        self._stop.set()
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.join()
        capture, self._capture = self._capture, None
        if capture is not None:
            capture.release()


def opencv_camera(address: str, **options: Any) -> OpenCvCamera:
    """An unconnected camera for `SOURCE[?settings]`."""
    source, settings = parse_camera_address(address)
    return OpenCvCamera(source, settings, **options)
