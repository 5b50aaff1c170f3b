"""An on-screen OpenGL window (GLFW, through the `glfw` package, with a moderngl context) that
shows RGB images: each image is uploaded to a texture and drawn over the whole window, then the
buffers are swapped with vsync on (swap interval 1).

GLFW is imported when a window opens, not before, so the rest of the rig runs where there is no
display at all. Without a display (no X server, no Wayland compositor) opening fails with one
RigError saying so.
"""

from __future__ import annotations

import contextlib
import re
from types import ModuleType
from typing import Any, Iterator

import moderngl
import numpy as np

from rig.devices.window_settings import WindowSettings
from rig.errors import RigError

BLIT_VERTEX_SHADER = """
#version 330
in vec2 in_corner;
out vec2 v_uv;
void main() {
    v_uv = vec2(0.5 + 0.5 * in_corner.x, 0.5 - 0.5 * in_corner.y);  // texture row 0 is the image's top
    gl_Position = vec4(in_corner, 0.0, 1.0);
}
"""
BLIT_FRAGMENT_SHADER = """
#version 330
uniform sampler2D image;
in vec2 v_uv;
out vec4 f_colour;
void main() {
    f_colour = vec4(texture(image, v_uv).rgb, 1.0);
}
"""


def _glfw() -> ModuleType:
    """GLFW, its errors raised as exceptions (not the package's default warnings)."""
    try:
        import glfw
    except ImportError as error:  # the library loads libglfw itself and may fail here
        raise RigError(f"cannot load GLFW for an on-screen window: {error}") from None
    glfw.ERROR_REPORTING = "raise"
    return glfw


def _no_window(error: Exception) -> RigError:
    # GLFW's message reads "(CODE) b'what happened'"
    text = re.sub(r"^\(\d+\) b'(.*)'$", r"\1", str(error))
    return RigError(f"cannot open a window ({text}): run on a desktop, set DISPLAY, or use xvfb-run for a virtual display")


class GlWindow:
    """One open window with its GL context (current on the thread that opened it)."""

    def __init__(self, settings: WindowSettings) -> None:
        glfw = self.glfw = _glfw()
        try:
            if not glfw.init():
                raise RigError("no display to open a window on: run on a desktop, set DISPLAY, or use xvfb-run")
        except glfw.GLFWError as error:
            raise _no_window(error) from None
        try:
            self.handle = self._create(settings)
        except glfw.GLFWError as error:
            glfw.terminate()
            raise _no_window(error) from None
        except BaseException:
            glfw.terminate()
            raise
        glfw.make_context_current(self.handle)
        glfw.swap_interval(1)
        self.ctx = moderngl.create_context(require=330)
        self.width, self.height = glfw.get_framebuffer_size(self.handle)
        self._program = self.ctx.program(vertex_shader=BLIT_VERTEX_SHADER, fragment_shader=BLIT_FRAGMENT_SHADER)
        corners = np.array([-1, -1, 1, -1, -1, 1, 1, 1], dtype=np.float32)
        self._vao = self.ctx.vertex_array(self._program, [(self.ctx.buffer(corners.tobytes()), "2f", "in_corner")])
        self._texture: Any = None
        glfw.make_context_current(None)

    def _create(self, settings: WindowSettings) -> Any:
        glfw = self.glfw
        monitors = glfw.get_monitors() or []
        if not monitors:
            raise RigError("the display server reports no monitor to open a window on")
        if not 0 <= settings.monitor < len(monitors):
            raise RigError(f"no monitor {settings.monitor}: this display has {len(monitors)} (0 to {len(monitors) - 1})")
        monitor = monitors[settings.monitor]
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
        glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
        glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
        glfw.window_hint(glfw.RESIZABLE, False)
        if settings.fullscreen:
            mode = glfw.get_video_mode(monitor)
            glfw.window_hint(glfw.REFRESH_RATE, mode.refresh_rate)
            handle = glfw.create_window(mode.size.width, mode.size.height, settings.title, monitor, None)
        else:
            handle = glfw.create_window(*settings.size, settings.title, None, None)
        if not handle:
            raise RigError("the display refused an OpenGL 3.3 core window; update the graphics driver")
        if not settings.fullscreen:
            x, y = settings.position if settings.position is not None else glfw.get_monitor_pos(monitor)
            glfw.set_window_pos(handle, x, y)
        return handle

    @property
    def rect(self) -> tuple[int, int, int, int]:
        """(x, y, width, height) of the window's drawing area on the screen, in pixels."""
        x, y = self.glfw.get_window_pos(self.handle)
        return (x, y, self.width, self.height)

    def extension_supported(self, name: str) -> bool:
        return bool(self.glfw.extension_supported(name))

    def proc_address(self, name: str) -> int:
        return int(self.glfw.get_proc_address(name) or 0)

    def native_glx(self) -> tuple[int, int] | None:
        """(X display, GLX drawable) where the window is on X11 with GLX, else None."""
        try:
            return int(self.glfw.get_x11_display() or 0), int(self.glfw.get_glx_window(self.handle) or 0)
        except Exception:  # noqa: BLE001 - a GLFW built without X11/GLX raises its own errors
            return None

    @contextlib.contextmanager
    def current(self) -> Iterator[None]:
        """The window's context current for what is inside, and none after: a thread has one current
        context across GLX and EGL, and the rig's renderers make their own (headless EGL) current
        when they draw, which they cannot while this one is."""
        self.glfw.make_context_current(self.handle)
        try:
            yield
        finally:
            self.glfw.make_context_current(None)

    def draw(self, image: np.ndarray) -> None:
        """Draw an RGB uint8 image (row 0 at the top) over the whole window's back buffer (inside
        `current()`)."""
        height, width = image.shape[:2]
        if self._texture is None or self._texture.size != (width, height):
            if self._texture is not None:
                self._texture.release()
            self._texture = self.ctx.texture((width, height), 3, dtype="f1")
            self._texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._texture.write(np.ascontiguousarray(image, dtype=np.uint8).tobytes())
        self.ctx.screen.use()
        self.ctx.viewport = (0, 0, self.width, self.height)
        self._texture.use(0)
        self._vao.render(mode=self.ctx.TRIANGLE_STRIP)

    def swap(self) -> None:
        """Swap the buffers and wait until the swap is done (glFinish): the time this returns is when
        the new image was handed to the display (inside `current()`)."""
        self.glfw.swap_buffers(self.handle)
        self.ctx.finish()

    def closing(self) -> bool:
        """Process the window's events; whether the user asked it to close."""
        self.glfw.poll_events()
        return bool(self.glfw.window_should_close(self.handle))

    def close(self) -> None:
        with self.current():
            if self._texture is not None:
                self._texture.release()
                self._texture = None
            self.ctx.release()
        self.glfw.destroy_window(self.handle)
        self.glfw.terminate()
