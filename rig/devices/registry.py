"""Devices chosen by a spec, `SCHEME[:ADDRESS]`, through one registry per kind of device.

    make_device("tracker", "sim", context)      the simulated tracker of a simulated run
    make_device("tracker", "mytracker:COM3")     a third party's, found through its entry point

The scheme names a factory registered for the kind (tracker, display, camera); the address, the
rest of the spec, goes to it. Built in: `sim` for every kind, the simulated twins of `rig.sim`,
which exist only inside a simulated run; for trackers also `serial:URL`, `hid:VID:PID[:PROFILE]`
and `lsl:NAME`, the real trackers of `rig.devices.trackers`; for displays `window[:MONITOR][?...]`, an
on-screen window (`rig.devices.window`); for cameras `camera:SOURCE[?...]`, a device, file or stream
read with OpenCV (`rig.devices.camera`), which writes its frames into the context's `out_dir`.
Third-party devices are entry points
in the groups `rig.trackers`, `rig.displays` and `rig.cameras` (see `rig.plugins`): a callable
taking `(address, context)` and returning an unconnected device that satisfies the kind's protocol
in `rig.devices.protocols`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from rig.devices.camera.opencv_camera import OpenCvCamera, opencv_camera
from rig.devices.protocols import Camera, Display, TrackerSource
from rig.devices.trackers.hid_tracker import hid_tracker
from rig.devices.trackers.lsl_tracker import lsl_tracker
from rig.devices.trackers.serial_tracker import serial_tracker
from rig.devices.trackers.stream import TrackerStream
from rig.devices.window.spec import window_display
from rig.errors import ConfigError, RigError
from rig.plugins import load_plugin, plugin_names

if TYPE_CHECKING:
    from rig.sim.world import SimulatedWorld


@dataclass(frozen=True)
class DeviceContext:
    """What a device factory may need beyond its address: the simulated world a `sim` twin lives in
    (None in a live run), and the folder a device that records its own data writes into."""

    simulation: SimulatedWorld | None = None
    out_dir: Path | None = None


DeviceFactory = Callable[[str, DeviceContext], Any]


@dataclass(frozen=True)
class DeviceKind:
    """A kind of device: its entry-point group, the protocol its devices satisfy, its built-ins."""

    name: str
    group: str
    protocol: type
    built_in: dict[str, DeviceFactory]


def _real_tracker(make: Callable[[str], TrackerStream]) -> DeviceFactory:
    return lambda address, context: make(address)


def _camera(address: str, context: DeviceContext) -> OpenCvCamera:
    if context.out_dir is None:
        raise ConfigError("a camera writes its frames as they come: it needs an output folder")
    return opencv_camera(address, context.out_dir)


def _simulated(kind: str) -> DeviceFactory:
    def make(address: str, context: DeviceContext) -> Any:
        if address:
            raise ConfigError(f"the simulated {kind} takes no address, got sim:{address}")
        if context.simulation is None:
            raise ConfigError(f"the simulated {kind} exists only in a simulated run (rig simulate, rig demo)")
        return getattr(context.simulation, kind)()

    return make


KINDS: dict[str, DeviceKind] = {
    kind.name: kind
    for kind in (
        DeviceKind(
            "tracker",
            "rig.trackers",
            TrackerSource,
            {
                "sim": _simulated("tracker"),
                "serial": _real_tracker(serial_tracker),
                "hid": _real_tracker(hid_tracker),
                "lsl": _real_tracker(lsl_tracker),
            },
        ),
        DeviceKind(
            "display", "rig.displays", Display, {"sim": _simulated("display"), "window": lambda a, c: window_display(a)}
        ),
        DeviceKind("camera", "rig.cameras", Camera, {"sim": _simulated("camera"), "camera": _camera}),
    )
}


def _kind(name: str) -> DeviceKind:
    try:
        return KINDS[name]
    except KeyError:
        raise ValueError(f"no device kind {name!r}; kinds: {', '.join(KINDS)}") from None


def device_schemes(kind: str) -> list[str]:
    """Every scheme a spec of this kind may start with, sorted: built-in and installed third-party."""
    device_kind = _kind(kind)
    return plugin_names(device_kind.group, device_kind.built_in)


def make_device(kind: str, spec: str, context: DeviceContext) -> Any:
    """A new, unconnected device of `kind` ("tracker", "display", "camera") for `spec`.

    Raises ConfigError for a scheme nothing is registered for, and RigError when a third-party
    factory fails or makes something that does not satisfy the kind's protocol.
    """
    device_kind = _kind(kind)
    scheme, _, address = spec.partition(":")
    plugin = load_plugin(device_kind.group, scheme, device_kind.built_in, kind)
    try:
        device = plugin.obj(address, context)
    except RigError:
        raise
    except Exception as exc:
        raise RigError(f"{kind} {spec!r} ({plugin.origin}) failed to start: {type(exc).__name__}: {exc}") from exc
    if not isinstance(device, device_kind.protocol):
        raise RigError(
            f"{kind} {spec!r} ({plugin.origin}) does not satisfy the {device_kind.protocol.__name__} protocol "
            "of rig.devices.protocols"
        )
    return device
