"""Real cameras: `OpenCvCamera` (the `camera:SOURCE` spec) and the frame files a capture writes."""

from rig.devices.camera.frames import FRAME_COLUMNS, FRAMES_FILE, VIDEO_FILE, FrameWriter
from rig.devices.camera.opencv_camera import (
    SETTINGS_FILE,
    CameraSettings,
    CameraSource,
    OpenCvCamera,
    apply_settings,
    opencv_camera,
    parse_camera_address,
)

__all__ = [
    "FRAMES_FILE",
    "FRAME_COLUMNS",
    "SETTINGS_FILE",
    "VIDEO_FILE",
    "CameraSettings",
    "CameraSource",
    "FrameWriter",
    "OpenCvCamera",
    "apply_settings",
    "opencv_camera",
    "parse_camera_address",
]
