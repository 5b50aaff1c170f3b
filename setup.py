"""The compiled parts, each with a pure-Python fallback where it is not built:

* analysis._jpeg_region, decoding a rectangle of a JPEG with the system's libjpeg(-turbo) (Debian:
  libjpeg62-turbo-dev);
* rig.devices.trackers._readers, the tracker reader threads (serial ports, LSL inlets) and a serial
  port's wait-and-read (POSIX threads).

Everything else is declared in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("analysis._jpeg_region", sources=["analysis/_jpeg_region.c"], libraries=["jpeg"]),
        Extension("rig.devices.trackers._readers", sources=["rig/devices/trackers/_readers.c"]),
    ]
)
