"""`rig emulate-tracker serial|lsl`: an emulated tracker for tests and demos.

    rig emulate-tracker serial --pty /tmp/tracker [--profile binary-pose] [--rate 1000] [--duration 10]
    rig emulate-tracker serial --tcp 7777 ...
    rig emulate-tracker lsl --name RigPose ...

It streams the simulated tracker (`rig.sim.tracker`: on the simulated pendulum, or --trace FILE
played in a loop) once a reader connects: exact and sent at once unless --noise-mm, --noise-deg,
--delay-ms, --jitter-ms or --dropout say otherwise, with --faults on demand; with --log FILE it
writes what became of every record it measured.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from rig.commands import options, outputs
from rig.errors import ConfigError
from rig.sim.fault_plan import FaultPlan, parse_faults
from rig.sim.tracker_config import TrackerConfig


def _faults(text: str) -> FaultPlan:
    try:
        return parse_faults(text)
    except ConfigError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def _run(args: argparse.Namespace) -> int:
    from rig.emulate import EmulatorConfig, make_sink, run_emulator

    if args.transport == "lsl":
        transport, address = "lsl", args.name
    else:
        transport, address = ("pty", str(args.pty)) if args.pty is not None else ("tcp", str(args.tcp))
    config = EmulatorConfig(
        transport=transport,
        address=address,
        tracker=TrackerConfig(
            rate_hz=args.rate,
            position_noise_m=args.noise_mm / 1e3,
            orientation_noise_deg=args.noise_deg,
            transport_delay_s=args.delay_ms / 1e3,
            jitter_s=args.jitter_ms / 1e3,
            dropout=args.dropout,
        ),
        duration_s=args.duration,
        profile=getattr(args, "profile", "binary-pose"),
        trace=args.trace,
        faults=args.faults,
        seed=args.seed,
        drift_ppm=getattr(args, "drift_ppm", 0.0),
        log=args.log,
    )
    sink = make_sink(config)
    config = replace(config, address=sink.address)
    spec = f"serial:{sink.address}?profile={config.profile}" if transport != "lsl" else sink.address
    try:
        counts = run_emulator(
            config,
            sink,
            lambda message: print(f"emulator: {message}", file=sys.stderr, flush=True),
            on_ready=lambda: print(f"emulated tracker ready: record it with --tracker {spec}", flush=True),
        )
    finally:
        sink.close()
    summary = {"tracker": spec, "faults": config.faults.label, "sent": counts.sent, "intact": counts.intact,
               "damaged": counts.damaged, "lost": counts.lost}  # fmt: skip
    print(json.dumps(summary) if args.json else ", ".join(f"{k} {v}" for k, v in summary.items()))
    return 0


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--rate", type=options.positive_float, default=1000.0, help="records a second (default: %(default)s)")
    parser.add_argument("--duration", type=options.positive_float, default=10.0, help="seconds to send (default: %(default)s)")
    parser.add_argument("--trace", type=Path, metavar="FILE", help="play this recorded trace in a loop (default: the simulated pendulum)")
    parser.add_argument("--noise-mm", type=options.non_negative_float, default=0.0, help="position noise, std-dev per axis (default: 0)")
    parser.add_argument("--noise-deg", type=options.non_negative_float, default=0.0, help="orientation noise, std-dev per axis (default: 0)")
    parser.add_argument("--delay-ms", type=options.non_negative_float, default=0.0, help="transport delay before each write (default: 0)")
    parser.add_argument("--jitter-ms", type=options.non_negative_float, default=0.0, help="mean of the exponential jitter added to it (default: 0)")
    parser.add_argument("--dropout", type=float, default=0.0, help="probability that a record is lost, never sent (default: 0)")
    parser.add_argument("--faults", type=_faults, default=parse_faults("none"), metavar="SPEC",
                        help="faults such as corrupt=0.01,drop=0.001,garbage=2,burst=8,stall=3:0.5,disconnect=5:0.5 "
                        "(default: none)")  # fmt: skip
    parser.add_argument("--seed", type=int, default=0, help="seed of the noise, jitter, dropouts and faults (default: %(default)s)")
    parser.add_argument("--log", type=outputs.csv_file, metavar="FILE.csv", help="write every record's seq, device time, write time and fate")
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    parser.set_defaults(func=_run)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `emulate-tracker serial|lsl`."""
    parser = subparsers.add_parser(
        "emulate-tracker",
        description=__doc__.split("\n\n")[0],
    )
    transports = parser.add_subparsers(dest="transport", required=True, metavar="TRANSPORT")
    serial = transports.add_parser("serial", help="records on a pseudo-terminal or a TCP socket, per a profile")
    where = serial.add_mutually_exclusive_group(required=True)
    where.add_argument("--pty", type=Path, metavar="LINK", help="make a pseudo-terminal reachable at this path (a symlink)")
    where.add_argument("--tcp", type=options.non_negative_int, metavar="PORT", help="serve on 127.0.0.1:PORT (0: any free port)")
    serial.add_argument("--profile", default="binary-pose", help="record format: a shipped profile or a .toml file (default: %(default)s)")
    serial.add_argument("--drift-ppm", type=float, default=0.0, help="the device clock's rate error in ppm (default: 0)")
    _common(serial)
    lsl = transports.add_parser("lsl", help="a 7-channel LSL pose stream")
    lsl.add_argument("--name", required=True, help="the stream's name")
    _common(lsl)
