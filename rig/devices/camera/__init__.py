"""Real cameras: `OpenCvCamera` (the `camera:SOURCE` spec, `rig.devices.camera.opencv_camera`)."""
