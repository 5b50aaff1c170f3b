"""The compiled parts, each with a pure-Python fallback where it is not built:

* analysis._jpeg_region, decoding a rectangle of a JPEG with the system's libjpeg(-turbo) (Debian:
  libjpeg62-turbo-dev);
* rig.devices.trackers._fd_reader, a serial tracker's reader thread and wait-and-read (POSIX threads).

Everything else is declared in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("analysis._jpeg_region", sources=["analysis/_jpeg_region.c"], libraries=["jpeg"]),
        Extension("rig.devices.trackers._fd_reader", sources=["rig/devices/trackers/_fd_reader.c"]),
    ]
)
