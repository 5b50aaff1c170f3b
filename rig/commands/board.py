"""`rig board ...`: the rig's microcontroller from the command line.

    rig board info                  who the board is, its counters and the clock offset
    rig board sync                  measure the clock offset (and, repeated, its drift)
    rig board record --out DIR --duration S [--blink]
                                    record encoder, photodiode and LED events as CSV (analysis/board/recording.py);
                                    with --blink, play the blink code first (for `rig analyse --board DIR`)
    rig board blink                 play the LED blink code (to align a camera to the board)
    rig board latency DIR           the latency from a recording's photodiode passages and encoder

The port is --port (a /dev/tty... path, an emulated board's pty, or any pyserial URL) or the
RIG_BOARD_PORT environment variable.
"""

from __future__ import annotations

import argparse
import json
import os
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from declared import Range, setting
from rig.board.settings import BoardSettings
from rig.commands import outputs
from rig.commands.declared_options import add_declared_options, config_from_args
from rig.commands.options import positive_float, run_seconds
from rig.errors import ConfigError, RigError
from rig.sim.config import MAX_HOURS
from rig.progress import ProgressBar

if TYPE_CHECKING:
    from analysis.board.blink_code import BlinkSchedule
    from rig.board.clock_sync import OffsetInterval
    from rig.board.microcontroller import Microcontroller

PORT_VARIABLE = "RIG_BOARD_PORT"
# How often the waiting commands look at the link and redraw their progress.
POLL_S = 0.2
BLINK_LEAD_S = 0.2
# Waited after the last bit, for the LED's switch-off to arrive.
BLINK_TAIL_S = 0.1
# How long past the wall-clock end of a blink the board's own clock may take to get there.
BOARD_CLOCK_LIMIT_S = 10.0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Registers `board info|sync|record|blink|latency`; each sets func(args) -> exit code."""
    board = subparsers.add_parser("board")
    commands = board.add_subparsers(dest="board_command", required=True, metavar="BOARD_COMMAND")

    info = commands.add_parser("info", help="identify the board; show its counters and the clock offset")
    _add_port(info)
    info.add_argument("--json", action="store_true", help="print one JSON object")
    info.set_defaults(func=run_info)

    sync = commands.add_parser("sync", help="measure the host-board clock offset, and its drift when repeated")
    _add_port(sync)
    add_declared_options(sync, SyncOptions)
    sync.add_argument("--json", action="store_true", help="print one JSON object")
    sync.set_defaults(func=run_sync)

    record = commands.add_parser("record", help="record encoder, photodiode and LED events as CSV files")
    _add_port(record)
    record.add_argument("--out", type=outputs.output_folder, required=True, help="folder for the CSV files (must not hold a recording)")
    record.add_argument("--duration", type=run_seconds, required=True, help="seconds to record")
    add_declared_options(record, BoardSettings)
    record.add_argument(
        "--blink",
        action="store_true",
        help="play the blink code at the start, then leave the LED lit: film it, release the pendulum after it, "
        "and `rig analyse VIDEO --board DIR` aligns the video to this recording",
    )
    add_declared_options(record, BlinkOptions)
    record.set_defaults(func=run_record)

    blink = commands.add_parser("blink", help="play the LED blink code, to align a camera's video to the board's clock")
    _add_port(blink)
    add_declared_options(blink, BlinkOptions)
    blink.add_argument("--out", type=outputs.output_folder, help="also record the LED changes (led.csv) and the schedule (blink.json) here")
    blink.add_argument("--json", action="store_true", help="print the schedule as one JSON object")
    blink.set_defaults(func=run_blink)

    latency = commands.add_parser("latency", help="latency from a recording: photodiode passages against the encoder")
    latency.add_argument("recording", type=Path, help="a `rig board record` folder")
    latency.add_argument("--max-latency-ms", type=positive_float, help="largest latency to consider (default 0.45 pendulum periods)")
    latency.add_argument("--json", action="store_true", help="print one JSON object")
    latency.add_argument("--plot", type=outputs.plot_file, help="also draw the fit into this PNG file")
    latency.set_defaults(func=run_latency)


@dataclass(frozen=True)
class SyncOptions:
    """`rig board sync`'s numbers, each declared with its option."""

    round_trips: int = setting(48, "", "round trips per measurement", Range(4.0, 10000.0, True, True), flag="--round-trips")
    repeat: int = setting(1, "", "measurements to make", Range(1.0, 100000.0, True, True), flag="--repeat")
    every: float = setting(2.0, "seconds", "seconds between measurements, at most an hour", Range(0.0, 3600.0, includes_high=True), flag="--every")


@dataclass(frozen=True)
class BlinkOptions:
    """The blink code's numbers (`rig board blink`, `rig board record --blink`), each declared with its option."""

    bits: int = setting(64, "bits", "bits of blink code", Range(1.0, 4096.0, True, True), flag="--bits")
    bit_ms: float = setting(50.0, "ms", "duration of one bit", Range(1.0, 10000.0, True, True), flag="--bit-ms")
    seed: int = setting(0xACE1, "", "code seed", Range(1.0, 65535.0, True, True), flag="--seed")
    level: int = setting(255, "", "LED level of a 1 bit (and after a recording's blink)", Range(1.0, 255.0, True, True), flag="--level")


def _add_port(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--port", default=os.environ.get(PORT_VARIABLE), help=f"serial port or pyserial URL of the board (default ${PORT_VARIABLE})")


def _port(args: argparse.Namespace) -> str:
    if not args.port:
        raise RigError(f"no board port: pass --port /dev/ttyACM0 (or your board's port), or set {PORT_VARIABLE}")
    return args.port


def _board(args: argparse.Namespace, **options: Any) -> Microcontroller:
    from rig.board.microcontroller import Microcontroller  # here, not above: the link loads pyserial and numpy

    return Microcontroller(_port(args), **options)


def _interval_dict(interval: OffsetInterval) -> dict[str, float]:
    return {"offset_s": interval.midpoint, "low_s": interval.low, "high_s": interval.high, "width_s": interval.width, "rig_time_s": interval.at}


def _wait(board: Microcontroller, seconds: float, progress: ProgressBar | None = None) -> None:
    """Waits `seconds` of wall time, watching the link and drawing progress."""
    start = time.monotonic()
    pause = threading.Event()
    while (elapsed := time.monotonic() - start) < seconds:
        board.check()
        if progress is not None:
            progress(elapsed, seconds)
        pause.wait(min(POLL_S, seconds - elapsed))
    board.check()
    if progress is not None:
        progress(seconds, seconds)


def run_info(args: argparse.Namespace) -> int:
    with _board(args) as board:
        status = board.status()
        interval = board.clock_model.latest
    report = {"identity": asdict(board.identity), "status": asdict(status), "clock": _interval_dict(interval), "link": board.counters}
    if args.json:
        print(json.dumps(report))
        return 0
    identity = board.identity
    print(f"{identity.name} firmware {identity.firmware}, protocol {identity.protocol}, {identity.cpu_hz / 1e6:g} MHz, clock {identity.tick_hz / 1e6:g} MHz")
    print(f"board time {status.board_time:.6f} s; clock offset {interval.midpoint:+.6f} s, known within {interval.width * 1e6:.0f} us")
    counters = {name: value for name, value in asdict(status).items() if name not in ("board_tick", "board_time", "stream")}
    print("board counters: " + ", ".join(f"{name} {value}" for name, value in counters.items()))
    return 0


def run_sync(args: argparse.Namespace) -> int:
    hours = (args.repeat - 1) * args.every / 3600.0
    if hours > MAX_HOURS:
        raise ConfigError(f"--repeat {args.repeat} --every {args.every:g} would take about {hours:.3g} hours, more than the "
                          f"{MAX_HOURS:g} hours the rig starts: repeat less often or fewer times")  # fmt: skip
    with _board(args, sync_round_trips=args.round_trips) as board:
        for _ in range(args.repeat - 1):
            _wait(board, args.every)
            board.sync()
        intervals = board.clock_model.intervals
        drift = board.clock_model.drift()
    if args.json:
        report = {"intervals": [_interval_dict(i) for i in intervals], "drift": asdict(drift) if drift else None, "link": board.counters}
        print(json.dumps(report))
        return 0
    for interval in intervals:
        print(f"at {interval.at:.3f} s: board - rig = {interval.midpoint:+.6f} s, within +-{interval.width * 5e5:.0f} us ({interval.round_trips} round trips)")
    if drift is not None:
        print(f"drift {drift.rate * 1e6:+.2f} ppm +- {drift.uncertainty * 1e6:.2f} ppm over {drift.baseline_s:.1f} s")
    return 0


def run_record(args: argparse.Namespace) -> int:
    if args.blink and _blink_seconds(args) > args.duration:
        raise RigError(f"--duration {args.duration:g} s is shorter than the blink ({_blink_seconds(args):.2f} s): record for longer")
    from rig.board.instrument import BoardInstrument
    from rig.clock import MonotonicClock

    settings = config_from_args(BoardSettings, args, ConfigError)
    instrument = BoardInstrument(_port(args), args.out, settings, options={"requested_s": args.duration, "blink": args.blink})
    clock = MonotonicClock()
    try:
        instrument.connect(clock)
        board, started = instrument.board, clock.now()
        if args.blink:
            _play_blink(board, args, args.out, ProgressBar("blinking"))
            board.set_led(args.level)
        _wait(board, max(args.duration - (clock.now() - started), 0.0), ProgressBar(f"recording {args.out}"))
        instrument.finish()
    finally:
        instrument.close()
    counts = instrument.recorder.counts
    print(f"recorded {args.duration:g} s in {args.out}: " + ", ".join(f"{count} {name}" for name, count in counts.items() if count))
    return 0


def run_blink(args: argparse.Namespace) -> int:
    from rig.board.recorder import BoardRecorder

    board = _board(args)
    recorder = BoardRecorder(args.out) if args.out else None
    if recorder is not None:
        board.add_listener(recorder)
    try:
        with board:
            schedule = _play_blink(board, args, args.out, ProgressBar("blinking"))
            report = _blink_report(board, schedule)
    finally:
        if recorder is not None:
            recorder.close()
    if args.json:
        print(json.dumps(report))
    else:
        print(f"blinked {schedule.bits} bits of {schedule.bit_s * 1e3:g} ms from board time {schedule.start_board_time:.6f} s (seed {schedule.seed})")
    return 0


def _blink_report(board: Microcontroller, schedule: BlinkSchedule) -> dict[str, Any]:
    return asdict(schedule) | {"start_rig_time": board.to_rig_time(schedule.start_board_time)}


def _play_blink(board: Microcontroller, args: argparse.Namespace, out: Path | None, progress: ProgressBar) -> BlinkSchedule:
    """Plays the blink code (writing blink.json into out, if given) and waits until it is over."""
    schedule = board.blink(bits=args.bits, bit_s=args.bit_ms / 1e3, seed=args.seed, level=args.level, start_in_s=BLINK_LEAD_S)
    if out is not None:
        (out / "blink.json").write_text(json.dumps(_blink_report(board, schedule), indent=2) + "\n")
    _wait(board, _blink_seconds(args), progress)
    board.wait_for_board_time(schedule.start_board_time + schedule.bits * schedule.bit_s + BLINK_TAIL_S, BOARD_CLOCK_LIMIT_S)
    return schedule


def _blink_seconds(args: argparse.Namespace) -> float:
    return BLINK_LEAD_S + args.bits * args.bit_ms / 1e3 + BLINK_TAIL_S


def run_latency(args: argparse.Namespace) -> int:
    from analysis.board.photodiode_latency import estimate_from_recording, plot_board_latency

    max_latency = args.max_latency_ms / 1e3 if args.max_latency_ms else None
    latency = estimate_from_recording(args.recording, max_latency_s=max_latency)
    if args.plot:
        plot_board_latency(args.recording, latency, args.plot)
    if args.json:
        print(json.dumps(latency.as_dict()))
        return 0
    print(
        f"board latency {latency.latency_s * 1e3:.3f} ms +- {latency.uncertainty_s * 1e3:.3f} ms "
        f"({latency.passages_used} of {latency.passages_seen} passages; photodiode at encoder count "
        f"{latency.photodiode_counts:.2f}; residuals {latency.rms_residual_s * 1e6:.0f} us rms; "
        f"pendulum period {latency.period_s:.3f} s)"
    )
    return 0
