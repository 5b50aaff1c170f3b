"""Where and how the rig's window opens, declared without the window's libraries (OpenGL, GLFW), so
that a live run's settings are read on the command line before any of them loads."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class WindowSettings:
    """Where and how the window opens: monitor index (0 the primary), full screen or a window of
    `size` at `position` (pixels; None lets the system place it), the title."""

    monitor: int = 0
    fullscreen: bool = False
    size: tuple[int, int] = (640, 480)
    position: tuple[int, int] | None = None
    title: str = "latency rig"
