"""The compiled parts:

* analysis._jpeg_region, decoding a rectangle of a JPEG with the system's libjpeg(-turbo) (Debian:
  libjpeg62-turbo-dev), with a pure-Python fallback where it is not built;
* rig.devices.trackers._readers, the tracker reader threads (serial ports with a file descriptor,
  LSL inlets; POSIX threads): where it is not built, serial ports are read through pyserial in
  Python and LSL trackers cannot be read.

Everything else is declared in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("analysis._jpeg_region", sources=["analysis/_jpeg_region.c"], libraries=["jpeg"]),
        Extension("rig.devices.trackers._readers", sources=["rig/devices/trackers/_readers.c"]),
    ]
)
