"""`rig bench trackers`: stream the simulated pendulum from `rig emulate-tracker` (a pseudo-terminal,
TCP, LSL), clean and with faults (1% of bytes corrupted and a 0.5 s disconnect; a disconnect for
LSL), record each with the rig's tracker source as `rig record-tracker` does, and report per case
what was sent, recorded, missing, fabricated and counted corrupt, the CPU per sample, and the
latency from the emulator's write to the sample's queueing for a predictor.

Declared here, without the bench's libraries, for the command line; `rig.bench.trackers` runs it.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass

from declared import Flag, Range, like, setting
from rig.bench.contract import Command, bench_in
from rig.commands.declared_options import add_declared_options
from rig.sim.tracker_config import TrackerConfig


@dataclass(frozen=True)
class TrackerBenchOptions:
    """The tracker bench's options, each declared on its field; each case runs in real time, so its
    duration is the bench's time."""

    rate_hz: float = like(TrackerConfig, "rate_hz", default=1000.0, flag=Flag("--rate", help="records a second the emulators send"))
    duration_s: float = setting(10.0, "seconds", "seconds per case, run in real time (at most ten minutes)",
                                Range(0.5, 600.0, True, True), flag="--duration")  # fmt: skip


def _options(parser: argparse.ArgumentParser) -> None:
    add_declared_options(parser, TrackerBenchOptions)
    parser.add_argument("--quick", dest="duration", action="store_const", const=2.0, help="2 s per case (a smoke test)")


SUBJECT = Command(
    name="trackers",
    help="the serial and LSL tracker sources fed by the emulators: loss, fabrication, CPU per sample, added latency",
    bench=bench_in("trackers"),
    options=_options,
    outputs={"json": "write the rows as a JSON list", "plot": "plot CPU per sample and latency per case"},
    runs="keep the recordings and emulator logs here (default: a temporary folder)",
)
