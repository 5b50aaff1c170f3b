"""`rig measure`: measure a real system's latency: the live rig and a camera together, then the video.

    rig measure --tracker SPEC --camera SPEC [--renderer warp|direct|external] [--duration S] --out DIR
    rig measure --self-test [--external] [--json]

The rig runs live (tracker, predictor, renderer, an on-screen window; or an external renderer over
LSL) while the camera films the pendulum's LED and the screen; then the video is analysed and the
latency printed with its 95 % interval beside the rig's own log's answer (and, with --board PORT,
the photodiode's: the rig board records beside the run into DIR/board). Everything is in DIR: the
run's logs as they were written, the video, and measure.json and measure.png with all three answers.
--guided says what to do and checks the first seconds of video before the long run. --self-test
runs the whole chain with stand-ins (an emulated tracker, a frame clock, a camera twin reading the
window back) under an X display such as xvfb-run, and checks that the video and the log agree.

The run's health verdict comes first: valid, degraded (exit 3, the number with its caveats) or
invalid (exit 4: the rig or its tracker stalled, so the stall is printed and no latency). A video
whose interval misses the whole run's latency by the log is a warning (exit 3) with both numbers.
A self-test whose video and log disagree exits 1.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

from analysis.options import SIDES, AnalysisOptions
from rig.cli import EXIT_UNTRUSTED, EXIT_WARNINGS
from rig.commands import choices, options, outputs
from rig.commands.declared_options import add_declared_options, config_from_args
from rig.commands.device_options import add_device_options
from rig.commands.record import add_camera_options
from rig.errors import ConfigError
from rig.live.config import EXTERNAL, LSL, RENDERER, RUN, LiveConfig
from rig.progress import ProgressBar

if TYPE_CHECKING:
    from rig.live.measure import MeasureReport

CHECK_SECONDS = 3.0
SELF_TEST_S = 20.0
EXIT_DISAGREE = 1
GUIDE = (
    "1. Set the pendulum swinging (a hand's width to each side) with the tracker and the LED on it.",
    "2. Point the camera at the LED and at the monitor the rig draws on; both in view, nothing else bright.",
    "3. The rig will film a few seconds and check them before the long run.",
)


def _interval(ci: Any) -> str:
    return f", 95% CI [{ci[0]:.1f}, {ci[1]:.1f}] ms" if ci else ", no interval"


INVALID_ADVICE = (
    "no latency: the run's own timing cannot be trusted, so its video would not show the system's latency; close "
    "other programs that load the machine (or give the rig a machine of its own) and measure again"
)


def _verdict_lines(report: MeasureReport) -> list[str]:
    health = report.health
    if not health["reasons"]:
        return [f"run: {health['status']}"]
    return [f"run: {health['status']}:", *(f"  {reason}" for reason in health["reasons"])]


def _lines(report: MeasureReport, kept: bool) -> list[str]:
    from analysis.caveat import caveat
    from rig.commands.formatting import warning_text
    from rig.live.measure import MEASURE_FILE, PLOT_FILE

    video, log = report.video, report.log
    if report.invalid:
        return [*_verdict_lines(report), INVALID_ADVICE, f"the run's records are in {report.out_dir}" if kept
                else "(the run was in a temporary folder; --out DIR keeps it)"]  # fmt: skip
    lines = [
        *_verdict_lines(report),
        f"latency (video): {video['latency_ms']:.1f} ms{_interval(video['ci95_ms'])} by {video['method']}",
        f"latency (rig log): {log['latency_ms']:.1f} ms (sensor to photon per frame: mean {log['sensor_to_photon_ms']['mean']:.1f} ms, "
        f"sd {log['sensor_to_photon_ms']['sd']:.1f} ms, {log['frames']} frames)",
    ]
    if report.board:
        lines.append(f"latency (photodiode): {report.board['latency_ms']:.1f} +- {report.board['sd_ms']:.1f} ms")
    lines += [warning_text(warning) for warning in video.get("warnings", [])]
    against = report.run["video_vs_log"]["warning"]
    if against:
        lines.append(warning_text(caveat(against["cause"], against["remedy"])))
    check = report.run.get("self_test")
    if check:
        verdict = "agree" if check["agree"] else "DISAGREE"
        lines.append(f"self-test: video and log differ by {check['difference_ms']:+.2f} ms (tolerance {check['tolerance_ms']:g} ms): {verdict}")
    if kept:
        lines.append(f"wrote {report.out_dir / MEASURE_FILE} and {report.out_dir / PLOT_FILE}")
    else:
        lines.append("(the run was in a temporary folder; --out DIR keeps it)")
    return lines


def _print(report: MeasureReport, as_json: bool, kept: bool = True) -> int:
    """Print the report; the exit status: invalid run, then a self-test's disagreement, then a
    degraded run or a video that misses the whole run, then 0."""
    from rig.live.health import VALID

    print(json.dumps(report.to_dict(), default=str) if as_json else "\n".join(_lines(report, kept)))
    if report.invalid:
        return EXIT_UNTRUSTED
    check = report.run.get("self_test")
    if check and not check["agree"]:
        return EXIT_DISAGREE
    if report.health["status"] != VALID or report.run["video_vs_log"]["warning"]:
        return EXIT_WARNINGS
    return 0


def _self_test(args: argparse.Namespace) -> int:
    from rig.live.selftest.run import self_test

    duration = args.duration or SELF_TEST_S
    how = {"renderer": args.renderer, "external": args.external, "progress": ProgressBar("self-test")}
    if args.out is not None:
        return _print(self_test(args.out, duration, overwrite=args.overwrite, **how), args.json)
    with tempfile.TemporaryDirectory(prefix="rig-measure-self-test-") as scratch:
        return _print(self_test(Path(scratch), duration, **how), args.json, kept=False)


def _guided_check(args: argparse.Namespace, led_side: str | None) -> None:
    from rig.live.camera_recording import check_first_seconds, record_camera
    from rig.session.run_files import VIDEO_FILE

    for step in GUIDE:
        print(step, file=sys.stderr)
    while True:
        folder = args.out / "check"
        record_camera(args.camera.removeprefix("camera:"), CHECK_SECONDS, folder, overwrite=True,
                      accept_refused=args.accept_camera_settings)  # fmt: skip
        problems = check_first_seconds(folder / VIDEO_FILE, led_side)
        if not problems:
            print(f"the first {CHECK_SECONDS:g} s look right: both blobs found, exposure not saturated", file=sys.stderr)
            return
        for problem in problems:
            print(f"check: {problem}", file=sys.stderr)
        if not sys.stdin.isatty():
            raise ConfigError("the guided check of the first seconds failed (see above); fix the bench and run again")
        input("fix it, then press Enter to check again (Ctrl-C to stop) ")


def _run(args: argparse.Namespace) -> int:
    from rig.devices.window.spec import parse_window_address
    from rig.live.measure import measure
    from rig.service.bench_profile import read_profile, with_profile

    if args.self_test:
        return _self_test(args)
    missing = [name for name in ("tracker", "camera", "out") if getattr(args, name) is None]
    if missing:
        raise ConfigError(f"rig measure needs --{', --'.join(missing)} (or --self-test)")
    settings, scanout = parse_window_address(args.display.removeprefix("window").removeprefix(":"))
    config = config_from_args(
        LiveConfig, args, ConfigError, tracker=args.tracker, predictor=args.predictor[0],
        predictor_params=args.predictor[1], duration_s=args.duration or LiveConfig.duration_s, window=settings,
        scanout_fraction=scanout, **({"renderer": EXTERNAL} if args.external else {}),
        **({"streams": None} if args.no_lsl else {}),
    )  # fmt: skip
    how = AnalysisOptions(led_roi=args.led_roi, sphere_roi=args.sphere_roi, led_side=args.led_side)
    if args.bench is not None:
        how = with_profile(how, read_profile(args.bench), args.bench)
    if args.guided:
        _guided_check(args, how.hinted().led_side)
        print("4. Filming: keep the pendulum swinging and the camera still.", file=sys.stderr)
    report = measure(
        config, args.camera.removeprefix("camera:"), args.out, board_port=args.board, options=how,
        accept_camera_settings=args.accept_camera_settings, overwrite=args.overwrite, progress=ProgressBar("measuring"),
    )  # fmt: skip
    return _print(report, args.json)


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `measure`."""
    parser = subparsers.add_parser(
        "measure",
        description=" ".join(__doc__.split("\n\n")[i].replace("\n", " ") for i in (0, 2, 3)),
        listings=lambda: "\n\n".join((choices.trackers_listing(), choices.renderers_listing(), choices.predictors_listing())),
    )
    add_device_options(parser)
    add_declared_options(parser, LiveConfig, {RENDERER: ""})
    parser.add_argument("--predictor", type=options.predictor_spec, default=("default", {}), metavar="NAME[:key=value,...]",
                        help="the pose predictor (listed below), with parameters or a `rig tune` file (default: default)")  # fmt: skip
    parser.add_argument(
        "--duration", type=options.run_seconds, metavar="S",
        help=f"seconds to run (default: {LiveConfig.duration_s:g}; self-test {SELF_TEST_S:g})",
    )  # fmt: skip
    add_declared_options(parser, LiveConfig, {RUN: ""})
    parser.add_argument("--led-side", choices=SIDES, help="which side of the video the LED is on")
    parser.add_argument("--bench", type=Path, metavar="FILE.toml",
                        help="the bench profile: its camera, display and layout are the video analysis's hints, each checked "
                        "against the video (--led-side and the regions win over it)")  # fmt: skip
    parser.add_argument("--board", metavar="PORT",
                        help="the rig board's serial port or pyserial URL: it records beside the run (DIR/board), and the "
                        "photodiode's latency is given too")  # fmt: skip
    add_declared_options(parser, LiveConfig, {LSL: ""})
    parser.add_argument("--no-lsl", action="store_true", help="publish nothing on LSL (the rig's own renderer only)")
    parser.add_argument("--guided", action="store_true", help="say what to do and check the first seconds of video first")
    parser.add_argument("--self-test", action="store_true", help="run the whole chain with stand-ins under an X display (xvfb-run)")
    parser.add_argument("--out", type=outputs.output_folder, metavar="DIR", help="folder for the run, the video and the results")
    parser.add_argument("--overwrite", action="store_true", help="replace a run already in DIR")
    parser.add_argument("--json", action="store_true", help="print the results as one JSON object")
    add_camera_options(parser)
    parser.set_defaults(func=_run)
