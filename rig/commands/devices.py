"""`rig devices`: the trackers this machine can see, each with the spec that records it:
serial ports, HID devices with their vendor and product ids, and LSL streams on the network."""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass

from declared import Flag, Range, setting
from rig.commands.declared_options import add_declared_options


@dataclass(frozen=True)
class Listing:
    """How long `rig devices` listens, declared with its option."""

    lsl_wait_s: float = setting(
        1.0, "seconds", "seconds to listen for LSL streams, at most ten minutes", Range(0.0, 600.0, True, True),
        flag=Flag("--lsl-wait", metavar="S"),
    )  # fmt: skip


def _run(args: argparse.Namespace) -> int:
    from rig.devices.trackers.discovery import hid_devices, lsl_streams, serial_ports

    found = {"serial": serial_ports(), "hid": hid_devices(), "lsl": lsl_streams(args.lsl_wait)}
    if args.json:
        print(json.dumps(found))
        return 0
    details = {
        "serial": lambda d: d["description"],
        "hid": lambda d: " ".join(filter(None, (d["manufacturer"], d["product"]))) + f" (usage page {d['usage_page']:#x}, usage {d['usage']:#x})",
        "lsl": lambda d: f"{d['type']}, {d['channels']} channels at {d['rate_hz']:g} Hz from {d['host']}",
    }
    titles = {"serial": "serial ports", "hid": "HID devices", "lsl": "LSL streams"}
    for kind, devices in found.items():
        print(f"{titles[kind]}: {len(devices) or 'none'}")
        for device in devices:
            print(f"  {device['spec']:40s} {details[kind](device)}")
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `devices`."""
    parser = subparsers.add_parser("devices", description=__doc__)
    add_declared_options(parser, Listing)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=_run)
