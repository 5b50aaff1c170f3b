"""The devices a live run uses, as options: `rig measure` and `rig check` take the same ones, so a
check speaks of the devices the run will open."""

from __future__ import annotations

import argparse

from rig.commands.record import CAMERA_SPECS

DISPLAY_SPECS = "window[:MONITOR][?fullscreen=1&size=WxH&pos=X,Y&scanout=F]"


def add_device_options(parser: argparse.ArgumentParser) -> None:
    """--tracker, --camera, --display and --external, as a live run reads them."""
    parser.add_argument("--tracker", metavar="SPEC", help="the tracker on the pendulum (listed below)")
    parser.add_argument("--camera", metavar="SPEC", help=f"the camera filming the LED and the screen: {CAMERA_SPECS}")
    parser.add_argument("--display", default="window", metavar="SPEC", help=f"the window: {DISPLAY_SPECS} (default: %(default)s)")
    parser.add_argument("--external", action="store_true", help="measure an external renderer over LSL instead (see docs/lsl.md)")
