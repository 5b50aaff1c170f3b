"""`rig check`: check the devices a run would use, before the run, in about ten seconds.

    rig check --tracker SPEC --camera SPEC [--display window...] [--duration S] [--out DIR] [--json]

The same device options as `rig measure`. The window is opened and images presented as a run does:
the display's refresh is measured from the swaps' timestamps, and whether they are paced; the camera
films for a few seconds: the frame rate it delivers against the one it reports, the settings it
took and its exposure read back; the tracker is listened to: its rate, the jitter of its arrivals
and its clock's offset from the rig's; and the disk of DIR is checked for room for the film at that
rate for the planned duration. Each check prints pass, warn or fail, what it measured and what to fix.

Exit status: 0 every check passed; 3 a check warned (the run can go ahead; read what to fix);
4 a check failed (fix it before the run); 2 a malformed option or spec.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from rig.cli import EXIT_UNTRUSTED, EXIT_WARNINGS
from rig.commands import choices, options, outputs
from rig.commands.device_options import add_device_options
from rig.commands.record import add_accept_camera_settings
from rig.live.config import LiveConfig

if TYPE_CHECKING:
    from rig.preflight import CheckReport


def table(report: CheckReport) -> str:
    """One line a check (status, device, what, measured), a fix under each that did not pass, and the
    overall status with the time the check took."""
    from rig.preflight.rows import STATUSES

    rows = report.rows
    device = max(len(row.device) for row in rows)
    what = max(len(row.what) for row in rows)
    lines = []
    for row in rows:
        lines.append(f"{row.status.upper():<5} {row.device:<{device}}  {row.what:<{what}}  {row.measured}")
        if row.fix:
            lines.append(f"{'':<5} {'':<{device}}  {'':<{what}}  fix: {row.fix}")
    counts = ", ".join(f"{sum(row.status == status for row in rows)} {status}" for status in STATUSES)
    lines.append(f"overall: {report.status} ({counts}) in {report.seconds:.1f} s")
    return "\n".join(lines)


def exit_status(status: str) -> int:
    from rig.preflight.rows import FAIL, PASS, WARN

    return {PASS: 0, WARN: EXIT_WARNINGS, FAIL: EXIT_UNTRUSTED}[status]


def _run(args: argparse.Namespace) -> int:
    from rig.preflight import CheckPlan, run_checks

    plan = CheckPlan(
        tracker=args.tracker, camera=args.camera, display=None if args.external else args.display,
        duration_s=args.duration, disk_folder=outputs.nearest_existing(args.out),
        accept_camera_settings=args.accept_camera_settings,
    )  # fmt: skip
    report = run_checks(plan)
    print(json.dumps(report.to_dict()) if args.json else table(report))
    return exit_status(report.status)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `check`."""
    parser = subparsers.add_parser(
        "check",
        description=" ".join(__doc__.split("\n\n")[i] for i in (0, 2, 3)).replace("\n", " "),
        epilog=choices.trackers_listing(),
    )
    add_device_options(parser)
    parser.add_argument("--duration", type=options.positive_float, default=LiveConfig.duration_s, metavar="S",
                        help="seconds the planned run lasts, for the disk check (default: %(default)g)")  # fmt: skip
    parser.add_argument("--out", type=outputs.output_folder, default=Path("."), metavar="DIR",
                        help="where the run will be written, for the disk check (default: this folder)")  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print the checks as one JSON object")
    add_accept_camera_settings(parser)
    parser.set_defaults(func=_run)
