"""Find renderers by spec: the rig's own, and third-party ones registered as entry points.

A spec is a name, optionally with options: `warp`, `warp:holes=2,recon=grid,views=2`. The options
are keyword arguments of the renderer's class (numbers where they read as numbers, else text); a
renderer without options is constructed without arguments.

A package provides a renderer by declaring, in its pyproject.toml,

    [project.entry-points."rig.renderers"]
    myname = "mypackage.module:MyRenderer"

where MyRenderer is a class constructed without arguments (and with keyword arguments for any
options it takes) that satisfies `rig.render.protocol.Renderer` (see `rig.plugins`).
"""

from __future__ import annotations

import inspect
from typing import Any

from rig.errors import ConfigError, RigError
from rig.plugins import RENDERER_GROUP, load_plugin, plugin_names
from rig.render.direct import DirectRenderer
from rig.render.protocol import Renderer
from rig.render.warp import WarpRenderer
from rig.render.warp_options import WarpOptions


BUILT_IN_RENDERERS: dict[str, type] = {"direct": DirectRenderer, "warp": WarpRenderer}
BUILT_IN_OPTIONS: dict[str, type] = {"warp": WarpOptions}
"""The options of built-in renderers that take them (their fields are the option names)."""


def renderer_names() -> list[str]:
    """Every renderer name `make_renderer` accepts, sorted: built-in and installed third-party."""
    return plugin_names(RENDERER_GROUP, BUILT_IN_RENDERERS)


def _value(text: str) -> Any:
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """(name, options) of a renderer spec NAME[:key=value,...]; ConfigError for a malformed one."""
    name, _, rest = spec.partition(":")
    options: dict[str, Any] = {}
    for item in filter(None, (part.strip() for part in rest.split(","))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip() or not value.strip():
            raise ConfigError(f"renderer options are key=value separated by commas, got {item!r} in {spec!r}")
        options[key.strip()] = _value(value.strip())
    return name.strip(), options


def _check_options(name: str, cls: Any, options: dict[str, Any]) -> None:
    """ConfigError naming the options `cls` does not take."""
    declared = BUILT_IN_OPTIONS.get(name)
    parameters = inspect.signature(declared or cls).parameters
    takes_any = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters.values()) and declared is None
    unknown = [key for key in options if key not in parameters and not takes_any]
    if unknown:
        known = [p for p in parameters if parameters[p].kind is not inspect.Parameter.VAR_KEYWORD]
        raise ConfigError(
            f"renderer {name!r} has no option {', '.join(map(repr, unknown))}; "
            + (f"its options: {', '.join(known)}" if known else "it takes no options")
        )


def make_renderer(spec: str) -> Renderer:
    """A new, unopened renderer for `spec` (NAME[:key=value,...]).

    Raises ConfigError for a name no renderer has, or options it does not take or accept, and
    RigError when an installed third-party renderer cannot be loaded or made, is registered twice,
    or does not satisfy the Renderer protocol.
    """
    name, options = parse_spec(spec)
    plugin = load_plugin(RENDERER_GROUP, name, BUILT_IN_RENDERERS, "renderer")
    if options:
        _check_options(name, plugin.obj, options)
    try:
        renderer = plugin.obj(**options)
    except ConfigError:
        raise
    except Exception as exc:
        raise RigError(f"renderer {name!r} ({plugin.origin}) failed to start: {type(exc).__name__}: {exc}") from exc
    if not isinstance(renderer, Renderer):
        raise RigError(
            f"renderer {name!r} ({plugin.origin}) does not satisfy the rig.render.protocol.Renderer protocol "
            "(name, per_display_frame, open, render_app_frame, render_display_frame, close)"
        )
    return renderer
