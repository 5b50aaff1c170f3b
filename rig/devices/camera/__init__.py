"""Real cameras: `OpenCvCamera` (the `camera:SOURCE` spec)."""

from rig.devices.camera.opencv_camera import (
    CameraSettings,
    CameraSource,
    OpenCvCamera,
    apply_settings,
    opencv_camera,
    parse_camera_address,
)

__all__ = ["CameraSettings", "CameraSource", "OpenCvCamera", "apply_settings", "opencv_camera", "parse_camera_address"]
