"""`rig devices`: the trackers this machine can see, each with the spec that records it:
serial ports, HID devices with their vendor and product ids, and LSL streams on the network."""

from __future__ import annotations

import argparse
import json

from rig.commands import options


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
    parser.add_argument("--lsl-wait", type=options.non_negative_float, default=1.0, metavar="S",
                        help="seconds to listen for LSL streams (default: %(default)s)")  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=_run)
