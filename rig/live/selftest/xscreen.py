"""Reading a rectangle of an X screen back (Xlib's XGetImage through ctypes), as the self-test's
camera twin does: what the X server shows there now, whichever program drew it."""

from __future__ import annotations

import ctypes
import ctypes.util

import numpy as np

from rig.errors import RigError

ALL_PLANES = 0xFFFFFFFF
Z_PIXMAP = 2


class _XImage(ctypes.Structure):
    _fields_ = [
        ("width", ctypes.c_int), ("height", ctypes.c_int), ("xoffset", ctypes.c_int), ("format", ctypes.c_int),
        ("data", ctypes.c_void_p), ("byte_order", ctypes.c_int), ("bitmap_unit", ctypes.c_int),
        ("bitmap_bit_order", ctypes.c_int), ("bitmap_pad", ctypes.c_int), ("depth", ctypes.c_int),
        ("bytes_per_line", ctypes.c_int), ("bits_per_pixel", ctypes.c_int),
    ]  # fmt: skip


class XScreen:
    """A connection of its own to the X server named by DISPLAY (one per thread)."""

    def __init__(self) -> None:
        name = ctypes.util.find_library("X11")
        if name is None:
            raise RigError("the self-test films the screen through libX11, which is not installed (Debian: libx11-6)")
        x11 = self._x11 = ctypes.CDLL(name)
        x11.XOpenDisplay.restype = ctypes.c_void_p
        x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
        x11.XDefaultRootWindow.restype = ctypes.c_ulong
        x11.XDefaultRootWindow.argtypes = [ctypes.c_void_p]
        x11.XGetImage.restype = ctypes.POINTER(_XImage)
        x11.XGetImage.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_int, ctypes.c_int, ctypes.c_uint,
                                  ctypes.c_uint, ctypes.c_ulong, ctypes.c_int]  # fmt: skip
        x11.XFree.argtypes = [ctypes.c_void_p]
        x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
        self._display = x11.XOpenDisplay(None)
        if not self._display:
            raise RigError("the self-test cannot reach the X server to film it (is DISPLAY set? run it under xvfb-run)")
        self._root = x11.XDefaultRootWindow(self._display)

    def grey(self, rect: tuple[int, int, int, int]) -> np.ndarray:
        """The screen's rectangle (x, y, width, height) as grey uint8, row 0 at the top."""
        x, y, width, height = rect
        image = self._x11.XGetImage(self._display, self._root, x, y, width, height, ALL_PLANES, Z_PIXMAP)
        if not image:
            raise RigError(f"the X server gave no image of {rect}; is the window on the screen?")
        try:
            info = image.contents
            if info.bits_per_pixel != 32:
                raise RigError(f"the self-test films 32-bit screens only; this one has {info.bits_per_pixel} bits a pixel")
            raw = ctypes.string_at(info.data, info.bytes_per_line * info.height)
        finally:
            self._x11.XFree(ctypes.cast(image.contents.data, ctypes.c_void_p))
            self._x11.XFree(ctypes.cast(image, ctypes.c_void_p))
        pixels = np.frombuffer(raw, dtype=np.uint8).reshape(height, info.bytes_per_line // 4, 4)[:, :width, :3]
        return pixels.max(axis=2)

    def close(self) -> None:
        if self._display:
            self._x11.XCloseDisplay(self._display)
            self._display = None
