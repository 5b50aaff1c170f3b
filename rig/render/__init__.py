"""Renderers, the system under test: they turn predicted poses into display images.

    from rig.render import make_renderer, renderer_names

The plug-in protocol is in `rig.render.protocol`; shared OpenGL helpers are in `rig.render.gl`.
"""

from declared.lazy import lazy_exports

__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "AppFrameRequest": "rig.render.protocol",
        "AppFrameResult": "rig.render.protocol",
        "DisplayFrameRequest": "rig.render.protocol",
        "DisplayFrameResult": "rig.render.protocol",
        "Renderer": "rig.render.protocol",
        "RenderSetup": "rig.render.protocol",
        "make_renderer": "rig.render.registry",
        "renderer_names": "rig.render.registry",
    },
)

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
