"""The one compiled part: analysis._jpeg_region, decoding a rectangle of a JPEG with the system's
libjpeg(-turbo) (Debian: libjpeg62-turbo-dev). Everything else is declared in pyproject.toml."""

from setuptools import Extension, setup

setup(
    ext_modules=[
        Extension("analysis._jpeg_region", sources=["analysis/_jpeg_region.c"], libraries=["jpeg"]),
    ]
)
