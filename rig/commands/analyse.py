"""`rig analyse VIDEO`: measure the latency between the LED and the rendered sphere in a video.

Exits 0 for a clean result, 3 (`rig.cli.EXIT_WARNINGS`) for a result that comes with warnings
(printed, and in the JSON), 2 for a user error.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import analysis
from analysis.cycles import DEFAULT_LATENCY_RANGE_S
from analysis.estimators.registry import DEFAULT_METHOD
from rig.cli import EXIT_WARNINGS
from rig.commands import options, outputs
from rig.commands.analyse_batch import check_batch_options, is_batch, run_batch_command
from rig.commands.choices import methods_listing
from rig.commands.formatting import board_line, summary_line
from rig.progress import ProgressBar
from rig.service import AnalysisRequest, analyse
from rig.service.batch import find_videos


def _run(args: argparse.Namespace) -> int:
    videos = find_videos(args.videos)
    request = AnalysisRequest(
        video=videos[0],
        fps=args.fps,
        led_roi=args.led_roi,
        sphere_roi=args.sphere_roi,
        led_side=args.led_side,
        method=args.method,
        latency_range_ms=args.latency_range,
        seed=args.seed,
        tracks_csv=args.csv,
        board=args.board,
        display_hz=args.display_hz,
        exposure_ms=args.exposure_ms,
        readout_ms=args.readout_ms,
    )
    if is_batch(args, videos):
        check_batch_options(args)
        return run_batch_command(args, request, videos)
    measurement = analyse(request, ProgressBar("analysing"))
    result, board = measurement.result, measurement.board
    if args.json:
        print(json.dumps(measurement.to_dict()))
    else:
        print(summary_line(result))
        if board is not None:
            print(board_line(board, result))
        for name, estimate in result.methods.items():
            if name != result.method:
                ci = f" (95% {estimate.ci95_ms[0]:.2f} to {estimate.ci95_ms[1]:.2f})" if estimate.ci95_ms else ""
                print(f"  {name}: {estimate.latency_ms:.2f} ms{ci}")
        for warning in result.warnings:
            print(f"warning: {warning}")
    if args.plot is not None:
        from analysis.plots import plot_tracks

        writes = outputs.LateWrites()
        writes.write(args.plot, lambda: plot_tracks(result, args.plot))
        writes.check()
    return EXIT_WARNINGS if result.warnings else 0


def _latency_range(text: str) -> tuple[float, float]:
    """LOW,HIGH in ms."""
    try:
        low, high = (float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LOW,HIGH in ms, got {text!r}") from None
    if not low < high:
        raise argparse.ArgumentTypeError(f"LOW must be below HIGH, got {text}")
    return low, high


def add_analysis_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--led-roi", type=options.roi, metavar="X,Y,W,H", help="region the LED swings in (pixels)")
    parser.add_argument("--sphere-roi", type=options.roi, metavar="X,Y,W,H", help="region the sphere moves in (pixels)")
    parser.add_argument("--fps", type=options.positive_float, help="camera frame rate, overriding the file's (needed for image folders)")
    parser.add_argument(
        "--led-side",
        choices=("left", "right"),
        help="the LED is the blob on this side (default: told apart by refresh steps, saturation, size and side)",
    )
    parser.add_argument(
        "--display-hz",
        type=options.positive_float,
        help="the display's refresh rate, if known (default: looked for in the video); it fixes how the camera samples it",
    )
    parser.add_argument(
        "--exposure-ms",
        type=options.positive_float,
        help="the camera's exposure in ms, if known (default: estimated from the LED's motion blur)",
    )
    parser.add_argument(
        "--readout-ms",
        type=options.non_negative_float,
        help="the camera's rolling-shutter readout in ms, top row to bottom row (0 for a global shutter), if known: "
        "each blob is then timed by its rows (default: any readout up to the frame interval is allowed for)",
    )


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    low, high = (v * 1e3 for v in DEFAULT_LATENCY_RANGE_S)
    parser = subparsers.add_parser(
        "analyse",
        help="measure latency from a video of the LED and the sphere",
        description="Track the LED and the rendered sphere and measure by how much the sphere lags. "
        "Without ROIs the two moving blobs are found and told apart by physical evidence (the display's refresh "
        "steps, the LED's saturation, size, side); when that does not decide, the command stops and asks for the "
        "ROIs. The interval allows for the camera's sampling of the display and for model misfit. Exit status: 0 "
        "clean, 3 measured with warnings (read them), 2 user error. Compiled fits are kept between runs "
        "(JAX_COMPILATION_CACHE_DIR chooses the folder).",
        epilog=methods_listing(),
    )
    parser.add_argument(
        "videos",
        type=Path,
        nargs="+",
        metavar="VIDEO",
        help="video file (mp4, avi, mov, mkv), folder of numbered images, folder of videos, or glob; "
        "more than one makes a batch",
    )
    add_analysis_options(parser)
    parser.add_argument("--method", choices=(*analysis.methods(), "all"), default=DEFAULT_METHOD, help="estimator (default: %(default)s)")
    parser.add_argument(
        "--latency-range",
        type=_latency_range,
        default=(low, high),
        metavar="LOW,HIGH",
        help=f"latencies considered, in ms, to fix the whole number of swing periods (default: {low:g},{high:g})",
    )
    parser.add_argument(
        "--board",
        type=Path,
        metavar="DIR",
        help="a `rig board record --blink` folder made while filming: the LED's blink code puts the video on the "
        "board's clock and the encoder's start of swing fixes the whole number of periods",
    )
    parser.add_argument("--seed", type=int, default=0, help="random seed of the bayes sampler (default: %(default)s)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--csv", type=outputs.csv_file, metavar="FILE.csv", help="write both tracks as CSV, row by row as they are measured")
    parser.add_argument(
        "--plot",
        type=outputs.plot_file,
        metavar="FILE.png",
        help="plot tracks, fits, residuals and latency over time (a batch: the summary's latencies, by default beside it)",
    )
    add_batch_options(parser)
    parser.set_defaults(func=_run)


def add_batch_options(parser: argparse.ArgumentParser) -> None:
    batch = parser.add_argument_group(
        "many videos",
        "Several videos, folders or globs make a batch: one row per video (a bad video is a failed row, the batch "
        "goes on), written as each finishes. Exit status 3 when any video failed or came with warnings.",
    )
    batch.add_argument("--summary", type=outputs.csv_file, metavar="FILE.csv", help="write the rows here, the same as JSON and a plot beside it")
    options.add_executor_options(batch, "the batch")
    batch.add_argument(
        "--labels",
        type=Path,
        metavar="FILE.csv",
        help="labels per video: a CSV whose first column is video (path or file name), one column per label "
        "(default: each video labelled by its folder)",
    )
    batch.add_argument("--group", metavar="LABEL", help="colour the summary plot by this label (default: the first)")
    batch.add_argument("--overwrite", action="store_true", help="replace an existing --summary")
