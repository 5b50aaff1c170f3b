"""`rig bench live`: the live loop's own overhead (see `rig.bench.live`)."""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from rig.commands import options, outputs


def _run(args: argparse.Namespace) -> int:
    from rig.bench import live

    with tempfile.TemporaryDirectory(prefix="rig-bench-live-") as scratch:
        folder = args.runs if args.runs is not None else Path(scratch)
        report = live.run_bench(args.duration, folder, lambda message: print(message, file=sys.stderr, flush=True))
    writes = outputs.LateWrites()
    if args.json is not None:
        writes.json(args.json, report)
    if args.plot is not None:
        writes.write(args.plot, lambda: live.plot(report, args.plot))
    print(live.table(report))
    print(f"machine noise: {report['cpus']} CPUs, 1-minute load average {report['load_average_1min']:.2f}")
    writes.check()
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
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the figures as JSON")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="plot the figures")
    parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR", help="keep the run's files here (default: a temporary folder)")
    parser.set_defaults(func=_run)
