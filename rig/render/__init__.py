"""Renderers, the system under test: they turn predicted poses into display images.

    from rig.render import make_renderer, renderer_names

The plug-in protocol is in `rig.render.protocol`; shared OpenGL helpers are in `rig.render.gl`.
"""

from rig.render.protocol import (
    AppFrameRequest,
    AppFrameResult,
    DisplayFrameRequest,
    DisplayFrameResult,
    Renderer,
    RenderSetup,
)
from rig.render.registry import make_renderer, renderer_names

__all__ = [
    "AppFrameRequest",
    "AppFrameResult",
    "DisplayFrameRequest",
    "DisplayFrameResult",
    "RenderSetup",
    "Renderer",
    "make_renderer",
    "renderer_names",
]
