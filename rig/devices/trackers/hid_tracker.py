"""`hid:VID:PID[:PROFILE]`: a tracker that sends USB HID input reports (an IMU, a headset), read
through hidapi; VID and PID in hex as `rig devices` lists them, PROFILE a shipped profile's name
or a .toml path (default hid-quat16).

The device is opened through an injected opener returning an object with hidapi's `hid.device`
methods (`read(max_length, timeout_ms)` giving a list of byte values, empty when none came in time;
`close()`); tests pass a fake that replays recorded reports.
"""

from __future__ import annotations

import errno
from typing import Callable, Protocol

from rig.devices.trackers.decoders import HidReportDecoder
from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.stream import TrackerStream, profile_stream
from rig.devices.trackers.transport import ThreadReader
from rig.errors import ConfigError, RigError

DEFAULT_PROFILE = "hid-quat16"
READ_TIMEOUT_MS = 50


class HidDevice(Protocol):
    """What a tracker needs of hidapi's `hid.device`."""

    def read(self, max_length: int, timeout_ms: int = 0) -> list[int]: ...

    def close(self) -> None: ...


def open_hid_device(vendor_id: int, product_id: int) -> HidDevice:
    """The default opener: hidapi's first device with these ids."""
    import hid

    device = hid.device()
    device.open(vendor_id, product_id)
    return device


def parse_hid_address(address: str) -> tuple[int, int, str]:
    """(vendor id, product id, profile) from `VID:PID[:PROFILE]`."""
    parts = address.split(":", 2)
    if len(parts) < 2:
        raise ConfigError(f"hid:{address}: expected hid:VID:PID[:PROFILE] with the ids in hex, such as hid:046d:c52b")
    try:
        vendor, product = (int(part, 16) for part in parts[:2])
    except ValueError:
        raise ConfigError(f"hid:{address}: the vendor and product ids must be hex numbers, such as hid:046d:c52b") from None
    if not (0 <= vendor <= 0xFFFF and 0 <= product <= 0xFFFF):
        raise ConfigError(f"hid:{address}: vendor and product ids are 16-bit (at most ffff)")
    return vendor, product, parts[2] if len(parts) > 2 and parts[2] else DEFAULT_PROFILE


class HidTransport:
    """One HID device's input reports, read through hidapi's Python binding by a `ThreadReader`
    (there is no compiled reader for HID): each report is a chunk."""

    def __init__(self, vendor: int, product: int, report_bytes: int, open_device: Callable[[int, int], HidDevice]) -> None:
        self.ids = f"{vendor:04x}:{product:04x}"
        self.description = f"HID device {self.ids}"
        self._vendor, self._product = vendor, product
        self._open_device = open_device
        self._read_bytes = max(report_bytes, 64)
        self._device: HidDevice | None = None
        self._origin_ns = 0

    def open(self, origin_ns: int) -> None:
        try:
            self._device = self._open_device(self._vendor, self._product)
        except (OSError, ValueError) as error:
            raise RigError(
                f"cannot open HID device {self.ids} ({error}): check that it is plugged in (`rig devices` lists "
                "what it sees) and that your user may read its /dev/hidraw* node (a udev rule)"
            ) from None
        self._origin_ns = origin_ns

    def reader(self) -> ThreadReader:
        return ThreadReader(self._receive, self._origin_ns, f"hid reader {self.ids}")

    def _receive(self) -> bytes | None:
        try:
            report = self._device.read(self._read_bytes, READ_TIMEOUT_MS)  # type: ignore[union-attr]
        except ValueError as error:  # hidapi's, for a device that went away
            raise OSError(errno.EIO, str(error)) from None
        return bytes(report) if report else None

    def upkeep(self) -> None:
        """Nothing: the device's clock is mapped from its records alone."""

    def close(self) -> None:
        device, self._device = self._device, None
        if device is not None:
            try:
                device.close()
            except (OSError, ValueError):
                pass


def hid_tracker(address: str, open_device: Callable[[int, int], HidDevice] = open_hid_device) -> TrackerStream:
    """An unconnected HID tracker for `VID:PID[:PROFILE]`."""
    vendor, product, profile_name = parse_hid_address(address)
    profile = load_profile(profile_name)
    if profile.format != "hid":
        raise ConfigError(f"profile {profile.name} is a {profile.format} profile; a HID tracker needs format = \"hid\"")
    decoder = HidReportDecoder(profile)
    transport = HidTransport(vendor, product, decoder.report_bytes, open_device)
    return profile_stream(f"hid:{address}", transport, decoder, profile)
