"""`rig bench live`: what the live loop itself adds, measured in one run: the rig runs live on an
emulated LSL tracker with a window paced at 60 Hz (under xvfb-run or a desktop), and the bench
reports the time from a sample's arrival to the pose the renderer gets, and from each buffer swap
to its logged row.

Declared here, without the bench's libraries, for the command line; `rig.bench.live` runs it.
"""

from __future__ import annotations

import argparse

from rig.bench.contract import Command, bench_in
from rig.commands import options


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration", type=options.run_seconds, default=10.0, help="seconds of live run (default: %(default)s)")


SUBJECT = Command(
    name="live",
    help="the live loop's overhead: sample arrival to the pose the renderer gets, swap to log (needs an X display)",
    bench=bench_in("live"),
    options=_options,
    outputs={"json": "write the figures as JSON", "plot": "plot the figures"},
    runs="keep the run's files here (default: a temporary folder)",
)
