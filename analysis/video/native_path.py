"""A path as the native video libraries (OpenCV, FFmpeg through PyAV) take it.

A file name the system accepts need not be valid UTF-8: on Linux any bytes but '/' and NUL are
allowed, and Python hands such a name on as a str holding surrogates (b"caf\\xe9.avi" becomes
'caf\\udce9.avi'). OpenCV cannot encode that str and crashes the process (a segmentation fault,
no message); PyAV raises a UnicodeEncodeError. Every path bound for those libraries goes through
`native_path`, which refuses such a name in one line instead.
"""

from __future__ import annotations

import os

from analysis.errors import AnalysisError


def shown_path(path: str | os.PathLike[str]) -> str:
    """The path as a person can read it: bytes that are not UTF-8 written as \\xNN."""
    return os.fsencode(path).decode("utf-8", "backslashreplace")


def native_path(path: str | os.PathLike[str]) -> str:
    """`path` as a str that OpenCV and PyAV can open; AnalysisError if its name is not UTF-8."""
    text = os.fspath(path)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise AnalysisError(
            f"{shown_path(text)}: the name is not valid UTF-8, which the video libraries cannot open; "
            "give the file or folder a name in UTF-8 and try again"
        ) from None
    return text
