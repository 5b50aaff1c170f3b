"""Devices chosen by a spec, `SCHEME[:ADDRESS]`, through one registry per kind of device.

    make_tracker("serial:/dev/ttyUSB0")           a real tracker
    make_tracker("mytracker:COM3")                a third party's, found through its entry point
    make_display("sim", DeviceContext(twins))     the twin a simulated run passes in

The scheme names a factory registered for the kind (tracker, display, camera); the address, the
rest of the spec, goes to it, and what it makes is checked against the kind's protocol in
`rig.devices.protocols`. Built in: for trackers `serial:URL`, `hid:VID:PID[:PROFILE]` and
`lsl:NAME`, the real trackers of `rig.devices.trackers`; for displays `window[:MONITOR][?...]`, an
on-screen window (`rig.devices.window`); for cameras `camera:SOURCE[?...]`, a device, file or
stream read with OpenCV (`rig.devices.camera`); and for every kind `sim`, the twin of that kind the
caller passes in its context (a simulated run passes its world's, `rig.sim.world`; the registry
knows nothing of the simulation). Third-party devices are entry points in the groups
`rig.trackers`, `rig.displays` and `rig.cameras` (see `rig.plugins`): a callable taking
`(address, context)` and returning an unconnected device.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Generic, Mapping, TypeVar, cast

from rig.devices.camera.opencv_camera import opencv_camera
from rig.devices.protocols import Camera, Display, TrackerSource
from rig.devices.trackers.hid_tracker import hid_tracker
from rig.devices.trackers.lsl_tracker import lsl_tracker
from rig.devices.trackers.serial_tracker import serial_tracker
from rig.devices.window.spec import window_display
from rig.errors import ConfigError, RigError
from rig.plugins import load_plugin

SIMULATED = "sim"
Device = TypeVar("Device")


@dataclass(frozen=True)
class DeviceContext:
    """What a device factory may need beyond its address: the twins of a simulated run, a factory
    per kind ("tracker", "display", "camera") that makes that kind's `sim` device (none in a live run)."""

    twins: Mapping[str, Callable[[], object]] = field(default_factory=dict)


DeviceFactory = Callable[[str, DeviceContext], object]


@dataclass(frozen=True)
class DeviceKind(Generic[Device]):
    """A kind of device: its name, entry-point group, the protocol its devices satisfy, its built-ins."""

    name: str
    group: str
    protocol: type
    """`Device` itself, a runtime-checkable protocol (which a type[...] field cannot hold)."""
    built_in: Mapping[str, DeviceFactory]

    def make(self, spec: str, context: DeviceContext) -> Device:
        """A new, unconnected device for `spec`. Raises ConfigError for a scheme nothing is
        registered for, and RigError when a third-party factory fails or makes something that does
        not satisfy the kind's protocol."""
        scheme, _, address = spec.partition(":")
        plugin = load_plugin(self.group, scheme, self.built_in, self.name)
        try:
            device = plugin.obj(address, context)
        except RigError:
            raise
        except Exception as exc:
            raise RigError(f"{self.name} {spec!r} ({plugin.origin}) failed to start: {type(exc).__name__}: {exc}") from exc
        if not isinstance(device, self.protocol):
            raise RigError(
                f"{self.name} {spec!r} ({plugin.origin}) does not satisfy the {self.protocol.__name__} protocol "
                "of rig.devices.protocols"
            )
        return cast(Device, device)


def _twin(kind: str) -> DeviceFactory:
    def make(address: str, context: DeviceContext) -> object:
        if address:
            raise ConfigError(f"the simulated {kind} takes no address, got {SIMULATED}:{address}")
        if kind not in context.twins:
            raise ConfigError(f"the simulated {kind} exists only in a simulated run (rig simulate, rig demo)")
        return context.twins[kind]()

    return make


TRACKERS: DeviceKind[TrackerSource] = DeviceKind(
    "tracker", "rig.trackers", TrackerSource,
    {SIMULATED: _twin("tracker"), "serial": lambda a, c: serial_tracker(a), "hid": lambda a, c: hid_tracker(a),
     "lsl": lambda a, c: lsl_tracker(a)},
)  # fmt: skip
DISPLAYS: DeviceKind[Display] = DeviceKind(
    "display", "rig.displays", Display, {SIMULATED: _twin("display"), "window": lambda a, c: window_display(a)}
)
CAMERAS: DeviceKind[Camera] = DeviceKind(
    "camera", "rig.cameras", Camera, {SIMULATED: _twin("camera"), "camera": lambda a, c: opencv_camera(a)}
)


def make_tracker(spec: str, context: DeviceContext = DeviceContext()) -> TrackerSource:
    """A new, unconnected tracker source for `spec` (see the module docstring)."""
    return TRACKERS.make(spec, context)


def make_display(spec: str, context: DeviceContext = DeviceContext()) -> Display:
    """A new, unconnected display for `spec`."""
    return DISPLAYS.make(spec, context)


def make_camera(spec: str, context: DeviceContext = DeviceContext()) -> Camera:
    """A new, unconnected camera for `spec`."""
    return CAMERAS.make(spec, context)
