"""Better swap timing than the time a swap returned, where the driver offers it.

* `GpuTimestamps` (GL_ARB_timer_query, OpenGL 3.3 core): a GL_TIMESTAMP query issued after a frame's
  drawing records when the GPU finished it, on the GPU's clock, mapped onto the rig's by reading
  both clocks together (re-read every `RESYNC_EVERY` frames).
* `OmlSyncValues` (GLX_OML_sync_control): the driver's count of vertical blanks (MSC) and the time
  of the latest (UST, microseconds on the system's monotonic clock on Linux), read right after each
  swap: the refresh a swap reached and when its blank was, not when the call came back.

Both are called through ctypes on the function pointers the window's GL context hands out, so
nothing here is imported or loaded unless a window is open. Each source can refuse itself
(`None` from its `open`) and the display then says which source it used.
"""

from __future__ import annotations

import ctypes
from typing import Any, Callable

from rig.clock import Clock, MonotonicClock

GL_TIMESTAMP = 0x8E28
GL_QUERY_RESULT = 0x8866
RESYNC_EVERY = 600
# A driver's UST further than this from the rig clock's now is not on the monotonic clock.
UST_PLAUSIBLE_S = 1.0

ProcAddress = Callable[[str], int]


class GpuTimestamps:
    """When the GPU finished each frame's drawing, on the rig clock."""

    source = "gl-timestamp"

    def __init__(self, proc_address: ProcAddress, clock: Clock) -> None:
        void = None
        self._clock = clock
        self._gen = ctypes.CFUNCTYPE(void, ctypes.c_int, ctypes.POINTER(ctypes.c_uint))(proc_address("glGenQueries"))
        self._counter = ctypes.CFUNCTYPE(void, ctypes.c_uint, ctypes.c_uint)(proc_address("glQueryCounter"))
        self._result = ctypes.CFUNCTYPE(void, ctypes.c_uint, ctypes.c_uint, ctypes.POINTER(ctypes.c_uint64))(
            proc_address("glGetQueryObjectui64v")
        )
        self._now = ctypes.CFUNCTYPE(void, ctypes.c_uint, ctypes.POINTER(ctypes.c_int64))(proc_address("glGetInteger64v"))
        query = ctypes.c_uint()
        self._gen(1, ctypes.byref(query))
        self._query = query.value
        self._frames = 0
        self._offset_s = 0.0
        self._sync()

    @classmethod
    def open(cls, proc_address: ProcAddress, extensions: set[str], clock: Clock) -> GpuTimestamps | None:
        """The source, or None where the context has no timer queries."""
        if "GL_ARB_timer_query" not in extensions:
            return None
        return cls(proc_address, clock)

    def _sync(self) -> None:
        gpu = ctypes.c_int64()
        before = self._clock.now()
        self._now(GL_TIMESTAMP, ctypes.byref(gpu))
        after = self._clock.now()
        self._offset_s = (before + after) / 2.0 - gpu.value / 1e9

    def mark(self) -> None:
        """Record the GPU's time once the drawing issued so far is done."""
        self._counter(self._query, GL_TIMESTAMP)

    def read(self) -> float:
        """The rig time the last `mark` was passed (waits for the GPU to get there)."""
        value = ctypes.c_uint64()
        self._result(self._query, GL_QUERY_RESULT, ctypes.byref(value))
        self._frames += 1
        if self._frames % RESYNC_EVERY == 0:
            self._sync()
        return value.value / 1e9 + self._offset_s


class OmlSyncValues:
    """The driver's blank counter and blank time after each swap."""

    source = "glx-oml-sync"

    def __init__(self, function: Any, display: int, drawable: int, origin_s: float) -> None:
        self._function = function
        self._display = display
        self._drawable = drawable
        self._origin_s = origin_s

    @classmethod
    def open(cls, proc_address: ProcAddress, supported: bool, display: int, drawable: int, clock: Clock) -> OmlSyncValues | None:
        """The source, or None where the driver lacks the extension or its UST is not on the rig's
        monotonic clock."""
        if not supported or not isinstance(clock, MonotonicClock):
            return None
        int64_p = ctypes.POINTER(ctypes.c_int64)
        function = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_ulong, int64_p, int64_p, int64_p)(
            proc_address("glXGetSyncValuesOML")
        )
        source = cls(function, display, drawable, clock.origin_ns / 1e9)
        values = source.read()
        if values is None or abs(values[1] - clock.now()) > UST_PLAUSIBLE_S:
            return None
        return source

    def read(self) -> tuple[int, float] | None:
        """(blank count, rig time of the latest blank), or None where the driver gave nothing."""
        ust, msc, sbc = ctypes.c_int64(), ctypes.c_int64(), ctypes.c_int64()
        if not self._function(self._display, self._drawable, ctypes.byref(ust), ctypes.byref(msc), ctypes.byref(sbc)):
            return None
        return int(msc.value), ust.value / 1e6 - self._origin_s
