"""What trackers this machine can see: serial ports, HID devices with their ids, LSL streams.
Each listing is a list of plain dicts (for `rig devices` and its --json); nothing is opened."""

from __future__ import annotations

from typing import Any

from serial.tools import list_ports

from rig.devices.trackers.lsl_tracker import resolve_streams


def serial_ports() -> list[dict[str, Any]]:
    return [
        {"spec": f"serial:{port.device}", "device": port.device, "description": port.description, "hwid": port.hwid}
        for port in sorted(list_ports.comports(), key=lambda p: p.device)
    ]


def hid_devices() -> list[dict[str, Any]]:
    import hid

    found = []
    for device in hid.enumerate():
        ids = f"{device['vendor_id']:04x}:{device['product_id']:04x}"
        found.append({
            "spec": f"hid:{ids}",
            "ids": ids,
            "manufacturer": device.get("manufacturer_string") or "",
            "product": device.get("product_string") or "",
            "usage_page": device.get("usage_page"),
            "usage": device.get("usage"),
            "interface": device.get("interface_number"),
            "path": device.get("path", b"").decode("utf-8", "replace"),
        })  # fmt: skip
    return found


def lsl_streams(wait_s: float) -> list[dict[str, Any]]:
    return [
        {
            "spec": f"lsl:{info.name()}",
            "name": info.name(),
            "type": info.type(),
            "channels": info.channel_count(),
            "rate_hz": info.nominal_srate(),
            "source_id": info.source_id(),
            "host": info.hostname(),
        }
        for info in resolve_streams(wait_s)
    ]
