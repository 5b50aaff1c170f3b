"""The camera's pre-flight check: the settings it took, the frame rate it delivers against the one it
reports, its exposure as read back, and the size of a filmed frame (for the disk check)."""

from __future__ import annotations

import cv2
import numpy as np

from rig.clock import Clock
from rig.devices.camera.opencv_camera import OpenCvCamera, opencv_camera
from rig.errors import RigError
from rig.preflight.rows import FAIL, PASS, WARN, CheckRow, failed, graded
from rig.writers import VideoRecord

DELIVERED_WARN = 0.95
"""A camera delivering less than this share of the rate it reports drops frames."""
DELIVERED_FAIL = 0.5
POLL_S = 0.02
EXPOSURE_FIX = "fix it with ?exposure=E in the camera's spec, short enough that the LED neither saturates nor blurs"


class CameraProbe:
    """Films with the camera `spec` (without the `camera:` prefix) on a thread of its own (the
    caller's `run`), keeping each frame's time and the last image, and turns them into rows."""

    def __init__(self, spec: str, accept_refused: bool) -> None:
        self.spec = spec
        self._accept_refused = accept_refused
        self._camera: OpenCvCamera = opencv_camera(spec, accept_refused=True)
        self._times: list[float] = []
        self._image: np.ndarray | None = None
        self._fault: str | None = None
        self._error: BaseException | None = None

    def run(self, clock: Clock, seconds: float) -> None:
        """Connect, take every frame for `seconds` from then, and close."""
        try:
            self._camera.connect(clock)
            until = clock.now() + seconds
            try:
                while clock.now() < until and self._fault is None:
                    for frame in self._camera.poll():
                        self._times.append(frame.t_start)
                        self._image = frame.image
                    fault = self._camera.fault()
                    self._fault = fault.reason if fault is not None else None
                    clock.wait_until(min(until, clock.now() + POLL_S))
            finally:
                self._camera.close()
        except BaseException as error:  # noqa: BLE001 - handed to the caller's thread by `rows`
            self._error = error

    @property
    def fps(self) -> float:
        """The rate the camera reports it films at (what the film is written at)."""
        return self._camera.fps

    def frame_bytes(self) -> int | None:
        """A filmed frame's size in the run's film (MJPEG at the film's quality), from the last frame."""
        if self._image is None:
            return None
        ok, encoded = cv2.imencode(".jpg", self._image, [cv2.IMWRITE_JPEG_QUALITY, VideoRecord.QUALITY])
        return int(encoded.size) if ok else None

    def rows(self, seconds: float) -> list[CheckRow]:
        """What the frames say; a camera that would not open is a failed row (any other error is the
        rig's own, raised here)."""
        if self._error is not None and not isinstance(self._error, RigError):
            raise self._error
        if self._error is not None:
            return [failed("camera", "frames", str(self._error), "check the camera's spec and cable (`rig devices` lists what it sees)")]
        return [self._settings_row(), self._rate_row(seconds), self._exposure_row()]

    def _settings_row(self) -> CheckRow:
        check = self._camera.check
        reported = check.reported
        size = f"{reported['size'][0]}x{reported['size'][1]}"
        values = {"requested": check.requested, "reported": reported, "refused": check.refused}
        if not check.refused:
            asked = ", ".join(f"{key} {value}" for key, value in check.requested.items()) or "nothing asked: the camera's own"
            return CheckRow("camera", "settings", PASS, f"{size}, {reported['fps']:g} fps ({asked})", values=values)
        status = WARN if self._accept_refused else FAIL
        return CheckRow("camera", "settings", status, f"refused: {'; '.join(check.refused)}",
                        "choose settings the camera offers" + ("" if self._accept_refused else ", or pass --accept-camera-settings"),
                        values)  # fmt: skip

    def _rate_row(self, seconds: float) -> CheckRow:
        reported = self._camera.fps
        frames = len(self._times)
        if self._fault is not None or frames < 2:
            why = self._fault or f"{frames} frames in {seconds:g} s"
            return failed("camera", "frame rate", why, "check the camera's cable and that no other program holds it")
        times = np.array(self._times)
        delivered = (frames - 1) / (times[-1] - times[0])
        status = graded(delivered / reported, DELIVERED_WARN, DELIVERED_FAIL) if reported > 0 else WARN
        values = {"delivered_fps": delivered, "reported_fps": reported, "frames": frames}
        measured = f"delivers {delivered:.2f} fps of the {reported:g} it reports ({frames} frames)"
        fix = "" if status == PASS else "it drops frames: lower the size, ask for fourcc=MJPG, give it a USB port of its own"
        return CheckRow("camera", "frame rate", status, measured, fix, values)

    def _exposure_row(self) -> CheckRow:
        check = self._camera.check
        exposure = check.reported["exposure"]
        values = {"exposure": exposure, "requested": check.requested.get("exposure")}
        if self._camera.source.kind == "file":
            return CheckRow("camera", "exposure", PASS, "a file: exposed as it was filmed", values=values)
        if "exposure" not in check.requested:
            return CheckRow("camera", "exposure", WARN, f"the camera's own (automatic): reads back {exposure:g}", EXPOSURE_FIX, values)
        if any(refused.startswith("exposure") for refused in check.refused):
            status = WARN if self._accept_refused else FAIL
            return CheckRow("camera", "exposure", status, f"asked {check.requested['exposure']:g}, reads back {exposure:g}", EXPOSURE_FIX, values)
        return CheckRow("camera", "exposure", PASS, f"{exposure:g} (as asked, in the camera's units)", values=values)
