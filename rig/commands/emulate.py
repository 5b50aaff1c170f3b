"""`rig emulate-tracker serial|lsl`: an emulated tracker for tests and demos.

    rig emulate-tracker serial --pty /tmp/tracker [--profile csv] [--rate 1000] [--duration 10]
    rig emulate-tracker serial --tcp 7777 ...
    rig emulate-tracker lsl --name RigPose ...

It streams the simulated tracker (`rig.sim.tracker`: on the simulated pendulum, or --trace FILE
played in a loop) once a reader connects: exact and sent at once unless --noise-mm, --noise-deg,
--delay-ms, --jitter-ms or --dropout say otherwise, with --faults on demand; with --log FILE it
writes what became of every record it measured. It ends when it has sent --duration seconds, when
its reader hangs up, or when no reader has come within --idle-timeout seconds; it never keeps
records for a reader that is not reading them (they are logged `unread`). Its default profile is
the serial tracker's, so `--tracker serial:PORT` reads it as it is.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass, replace
from pathlib import Path

from declared import Flag, Range, like, setting
from rig.commands import options, outputs
from rig.commands.declared_options import add_declared_option, add_declared_options, config_from_args
from rig.devices.trackers.default_profiles import SERIAL as DEFAULT_PROFILE
from rig.emulator_settings import ReaderWait
from rig.errors import ConfigError
from rig.sim.fault_plan import FaultPlan, parse_faults
from rig.sim.tracker_config import TrackerConfig


SERIAL = "serial"
"""The group of the options only the serial emulator takes."""


@dataclass(frozen=True)
class EmulatorOptions:
    """The emulator's numbers, each declared with its option: the tracker's as the simulated
    tracker's are (`rig.sim.tracker.TrackerConfig`, exact and sent at once unless given), how long it
    sends, its seed, and a serial device clock's rate error."""

    rate_hz: float = like(TrackerConfig, "rate_hz", default=1000.0, flag=Flag("--rate", help="records a second"))
    duration_s: float = setting(10.0, "seconds", "seconds to send, at most a day", Range(0.0, 86400.0, includes_high=True), flag="--duration")
    position_noise_m: float = like(TrackerConfig, "position_noise_m", default=0.0, flag=Flag("--noise-mm", unit="mm", factor=1e3))
    orientation_noise_deg: float = like(TrackerConfig, "orientation_noise_deg", default=0.0, flag=Flag("--noise-deg"))
    transport_delay_s: float = like(TrackerConfig, "transport_delay_s", default=0.0, flag=Flag("--delay-ms", unit="ms", factor=1e3))
    jitter_s: float = like(TrackerConfig, "jitter_s", default=0.0, flag=Flag("--jitter-ms", unit="ms", factor=1e3))
    dropout: float = like(TrackerConfig, "dropout", default=0.0, flag=Flag("--dropout"))
    seed: int = setting(0, "", "seed of the noise, jitter, dropouts and faults", Range(0.0, 1e9, True, True), flag="--seed")
    drift_ppm: float = setting(
        0.0, "ppm", "the device clock's rate error: a crystal's is tens of ppm", Range(-1000.0, 1000.0, True, True),
        flag=Flag("--drift-ppm", group=SERIAL),
    )  # fmt: skip

    def tracker(self) -> TrackerConfig:
        """The simulated tracker of these numbers (its settings not declared here at their defaults)."""
        shared = TrackerConfig.__dataclass_fields__.keys() & self.__dataclass_fields__.keys()
        return TrackerConfig(**{name: getattr(self, name) for name in shared})


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
    numbers = config_from_args(EmulatorOptions, args, ConfigError)
    config = EmulatorConfig(
        transport=transport,
        address=address,
        tracker=numbers.tracker(),
        duration_s=numbers.duration_s,
        profile=getattr(args, "profile", DEFAULT_PROFILE),
        trace=args.trace,
        faults=args.faults,
        seed=numbers.seed,
        drift_ppm=numbers.drift_ppm,
        log=args.log,
        idle_timeout_s=args.idle_timeout,
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
               "damaged": counts.damaged, "lost": counts.lost, "unread": counts.unread}  # fmt: skip
    print(json.dumps(summary) if args.json else ", ".join(f"{k} {v}" for k, v in summary.items()))
    return 0


def _common(parser: argparse.ArgumentParser, serial: bool) -> None:
    add_declared_options(parser, EmulatorOptions, {SERIAL: ""} if serial else {})
    parser.add_argument("--trace", type=Path, metavar="FILE", help="play this recorded trace in a loop (default: the simulated pendulum)")
    parser.add_argument("--faults", type=_faults, default=parse_faults("none"), metavar="SPEC",
                        help="faults such as corrupt=0.01,drop=0.001,garbage=2,burst=8,stall=3:0.5,disconnect=5:0.5 "
                        "(default: none)")  # fmt: skip
    parser.add_argument("--log", type=outputs.csv_file, metavar="FILE.csv", help="write every record's seq, device time, write time and fate")
    add_declared_option(parser, ReaderWait, "idle_timeout_s")
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
    serial.add_argument("--profile", default=DEFAULT_PROFILE,
                        help="record format: a shipped profile or a .toml file (default: %(default)s, as the serial tracker reads)")  # fmt: skip
    _common(serial, serial=True)
    lsl = transports.add_parser("lsl", help="a 7-channel LSL pose stream")
    lsl.add_argument("--name", required=True, help="the stream's name")
    _common(lsl, serial=False)
