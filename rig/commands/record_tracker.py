"""`rig record-tracker --tracker SPEC --duration S --out DIR`: record a real tracker's samples.

Writes DIR/tracker.csv (the rig's tracker sample format, for `rig bench predictors --trace` and
`rig tune --trace`), DIR/tracker_device.csv (the device's own time, counter and angular rate, row
for row) and DIR/tracker.json (device, profile, clock mapping, counters, link events). Ctrl-C stops
cleanly and keeps every sample.
"""

from __future__ import annotations

import argparse
import json

from rig.commands import choices, options, outputs
from rig.progress import ProgressBar
from rig.errors import RigError
from rig.fresh_outputs import removed_unless_recorded


def _summary(sidecar: dict) -> str:
    counters = sidecar.get("counters", {})
    lines = [f"recorded {sidecar['samples']} samples from {sidecar['spec']} in {sidecar['duration_s']:.1f} s"]
    if counters:
        lines.append(", ".join(f"{name.replace('_', '-')} {value if value is not None else 'unknown'}" for name, value in counters.items()))
    latency = sidecar.get("latency")
    if latency and latency["samples"]:
        lines.append(f"tracker latency to the host: median {latency['median_ms']:.3f} ms, 95th percentile {latency['p95_ms']:.3f} ms")
    mapping = sidecar.get("clock_mapping", {})
    if mapping.get("drift_ppm") is not None:
        lines.append(f"device clock drift {mapping['drift_ppm']:.1f} +- {mapping['drift_uncertainty_ppm']:.1f} ppm")
    for event in sidecar.get("events", []):
        lines.append(f"at {event['t']:.3f} s: link {event['what']}: {event['detail']}")
    return "\n".join(lines)


def _run(args: argparse.Namespace) -> int:
    from rig.service.tracker_recording import record_tracker

    bar = ProgressBar("recording") if args.duration is not None else (lambda done, total: None)
    with removed_unless_recorded(args.out):
        recording = record_tracker(args.tracker, args.duration, args.out, overwrite=args.overwrite, progress=bar)
        if args.json:
            print(json.dumps(recording.sidecar))
        else:
            print(_summary(recording.sidecar))
        if recording.sidecar["samples"] == 0:
            raise RigError(
                f"no sample arrived from {args.tracker} in {recording.sidecar['duration_s']:.1f} s: is the tracker on and "
                "streaming, and does the profile match its records? (its link counters are above; nothing was written)"
            )
    if not args.json:
        print(f"wrote {args.out}")
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `record-tracker`."""
    parser = subparsers.add_parser(
        "record-tracker",
        description=__doc__.split("\n\n")[0] + " " + __doc__.split("\n\n")[1].replace("\n", " "),
        listings=choices.trackers_listing,
    )
    parser.add_argument("--tracker", required=True, metavar="SPEC", help="the tracker (listed below)")
    parser.add_argument("--duration", type=options.run_seconds, metavar="S", help="seconds to record (default: until Ctrl-C)")
    parser.add_argument("--out", type=outputs.output_folder, required=True, metavar="DIR", help="folder to write tracker.csv and its sidecar into")
    parser.add_argument("--overwrite", action="store_true", help="replace a recording already in DIR")
    parser.add_argument("--json", action="store_true", help="print the sidecar as one JSON object")
    parser.set_defaults(func=_run)
