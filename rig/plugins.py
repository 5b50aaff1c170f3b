"""Things found by name: the rig's own, and third-party ones installed as entry points.

A package provides one by declaring, in its pyproject.toml, an entry point in the group of its
kind (`rig.renderers`, `rig.trackers`, `rig.displays`, `rig.cameras`):

    [project.entry-points."rig.trackers"]
    mytracker = "mypackage.module:MyTracker"

The rig's built-in names take precedence over entry points, so an installed package cannot
replace one of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points
from typing import Any, Mapping

from rig.errors import ConfigError, RigError

RENDERER_GROUP = "rig.renderers"
"""The entry-point group of renderers (`rig.render.registry`)."""


def plugin_names(group: str, built_in: Mapping[str, Any]) -> list[str]:
    """Every name `load_plugin` accepts for `group`, sorted: built-in and installed third-party."""
    return sorted(built_in.keys() | {ep.name for ep in entry_points(group=group)})


@dataclass(frozen=True)
class Plugin:
    """What `load_plugin` found: the registered object and where it came from (for messages)."""

    name: str
    obj: Any
    origin: str


def load_plugin(group: str, name: str, built_in: Mapping[str, Any], what: str) -> Plugin:
    """What is registered as `name`: a built-in one, else the one entry point of that name.

    `what` names the kind for messages ("renderer", "tracker"). Raises ConfigError for a name
    nothing has, and RigError when an installed entry point is registered twice or fails to load.
    """
    if name in built_in:
        return Plugin(name, built_in[name], "built in")
    candidates = [ep for ep in entry_points(group=group) if ep.name == name]
    if not candidates:
        raise ConfigError(f"unknown {what} {name!r}; available {what}s: {', '.join(plugin_names(group, built_in))}")
    if len(candidates) > 1:
        raise RigError(
            f"{what} {name!r} is registered by several installed distributions "
            f"({', '.join(distribution(ep) for ep in candidates)}); uninstall all but one"
        )
    entry_point = candidates[0]
    origin = f"{entry_point.value} from distribution {distribution(entry_point)}"
    try:
        return Plugin(name, entry_point.load(), origin)
    except Exception as exc:
        raise RigError(
            f"{what} {name!r} ({origin}) failed to load: {type(exc).__name__}: {exc}; "
            "fix or reinstall that distribution"
        ) from exc


def distribution(entry_point: EntryPoint) -> str:
    """The name and version of the distribution that installed an entry point."""
    dist = entry_point.dist
    return f"{dist.name} {dist.version}" if dist is not None else "(unknown distribution)"
