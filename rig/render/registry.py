"""Find renderers by name: the rig's own, and third-party ones registered as entry points.

A package provides a renderer by declaring, in its pyproject.toml,

    [project.entry-points."rig.renderers"]
    myname = "mypackage.module:MyRenderer"

where MyRenderer is a class constructed without arguments that satisfies
`rig.render.protocol.Renderer`. The rig's built-in names take precedence over entry points.
"""

from __future__ import annotations

from importlib.metadata import EntryPoint, entry_points

from rig.errors import ConfigError, RigError
from rig.render.direct import DirectRenderer
from rig.render.protocol import Renderer
from rig.render.warp import WarpRenderer

ENTRY_POINT_GROUP = "rig.renderers"

BUILT_IN_RENDERERS: dict[str, type] = {"direct": DirectRenderer, "warp": WarpRenderer}


def renderer_names() -> list[str]:
    """Every renderer name `make_renderer` accepts, sorted: built-in and installed third-party."""
    return sorted(BUILT_IN_RENDERERS.keys() | {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)})


def make_renderer(name: str) -> Renderer:
    """A new, unopened renderer called `name`.

    Raises ConfigError for a name no renderer has, and RigError when an installed third-party
    renderer cannot be loaded, is registered twice, or does not satisfy the Renderer protocol.
    """
    if name in BUILT_IN_RENDERERS:
        return BUILT_IN_RENDERERS[name]()
    candidates = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == name]
    if not candidates:
        raise ConfigError(f"unknown renderer {name!r}; available renderers: {', '.join(renderer_names())}")
    if len(candidates) > 1:
        raise RigError(
            f"renderer {name!r} is registered by several installed distributions "
            f"({', '.join(_distribution(ep) for ep in candidates)}); uninstall all but one"
        )
    entry_point = candidates[0]
    try:
        renderer = entry_point.load()()
    except Exception as exc:
        raise RigError(
            f"renderer {name!r} ({entry_point.value}) from distribution {_distribution(entry_point)} "
            f"failed to load: {type(exc).__name__}: {exc}; fix or reinstall that distribution"
        ) from exc
    if not isinstance(renderer, Renderer):
        raise RigError(
            f"renderer {name!r} ({entry_point.value}) from distribution {_distribution(entry_point)} "
            "does not satisfy the rig.render.protocol.Renderer protocol (name, per_display_frame, "
            "open, render_app_frame, render_display_frame, close)"
        )
    return renderer


def _distribution(entry_point: EntryPoint) -> str:
    dist = entry_point.dist
    return f"{dist.name} {dist.version}" if dist is not None else "(unknown distribution)"
