"""Find renderers by name: the rig's own, and third-party ones registered as entry points.

A package provides a renderer by declaring, in its pyproject.toml,

    [project.entry-points."rig.renderers"]
    myname = "mypackage.module:MyRenderer"

where MyRenderer is a class constructed without arguments that satisfies
`rig.render.protocol.Renderer` (see `rig.plugins`).
"""

from __future__ import annotations

from rig.errors import RigError
from rig.plugins import load_plugin, plugin_names
from rig.render.direct import DirectRenderer
from rig.render.protocol import Renderer
from rig.render.warp import WarpRenderer

ENTRY_POINT_GROUP = "rig.renderers"

BUILT_IN_RENDERERS: dict[str, type] = {"direct": DirectRenderer, "warp": WarpRenderer}


def renderer_names() -> list[str]:
    """Every renderer name `make_renderer` accepts, sorted: built-in and installed third-party."""
    return plugin_names(ENTRY_POINT_GROUP, BUILT_IN_RENDERERS)


def make_renderer(name: str) -> Renderer:
    """A new, unopened renderer called `name`.

    Raises ConfigError for a name no renderer has, and RigError when an installed third-party
    renderer cannot be loaded or made, is registered twice, or does not satisfy the Renderer protocol.
    """
    plugin = load_plugin(ENTRY_POINT_GROUP, name, BUILT_IN_RENDERERS, "renderer")
    try:
        renderer = plugin.obj()
    except Exception as exc:
        raise RigError(f"renderer {name!r} ({plugin.origin}) failed to start: {type(exc).__name__}: {exc}") from exc
    if not isinstance(renderer, Renderer):
        raise RigError(
            f"renderer {name!r} ({plugin.origin}) does not satisfy the rig.render.protocol.Renderer protocol "
            "(name, per_display_frame, open, render_app_frame, render_display_frame, close)"
        )
    return renderer
