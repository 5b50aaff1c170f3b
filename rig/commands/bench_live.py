"""`rig bench live`: the live loop's own overhead (see `rig.bench.live`)."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

from rig.commands import options


def _run(args: argparse.Namespace) -> int:
    from rig.bench import live

    with tempfile.TemporaryDirectory(prefix="rig-bench-live-") as scratch:
        folder = args.runs if args.runs is not None else Path(scratch)
        report = live.run_bench(args.duration, folder, lambda message: print(message, file=sys.stderr, flush=True))
        if args.json is not None:
            args.json.write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
        if args.plot is not None:
            live.plot(report, args.plot)
    print(live.table(report))
    print(f"machine noise: {report['cpus']} CPUs, 1-minute load average {report['load_average_1min']:.2f}")
    return 0


def add_live(benchmarks: argparse._SubParsersAction) -> None:
    """Register `bench live`."""
    parser = benchmarks.add_parser(
        "live",
        help="the live loop's overhead: sample arrival to the pose the renderer gets, swap to log (needs an X display)",
        description="Run the rig live on an emulated LSL tracker with a window paced at 60 Hz (under xvfb-run or a "
        "desktop) and report the time from a sample's arrival to the pose the renderer gets, and from each buffer swap "
        "to its logged row.",
    )
    parser.add_argument("--duration", type=options.positive_float, default=10.0, help="seconds of live run (default: %(default)s)")
    parser.add_argument("--json", type=Path, metavar="OUT", help="write the figures as JSON")
    parser.add_argument("--plot", type=Path, metavar="OUT.png", help="plot the figures")
    parser.add_argument("--runs", type=Path, metavar="DIR", help="keep the run's files here (default: a temporary folder)")
    parser.set_defaults(func=_run)
