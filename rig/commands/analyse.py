"""`rig analyse VIDEO`: measure the latency between the LED and the rendered sphere in a video.

Exits 0 for a clean result, 3 (`rig.cli.EXIT_WARNINGS`) for a result that comes with warnings
(printed, and in the JSON), 2 for a user error.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from analysis.errors import AnalysisError
from analysis.options import AnalysisOptions
from rig.cli import EXIT_WARNINGS
from rig.commands import options, outputs
from rig.commands.choices import methods_listing
from rig.commands.declared_options import add_declared_options, config_from_args
from rig.progress import ProgressBar


def _run(args: argparse.Namespace) -> int:
    from rig.commands.analyse_batch import check_batch_options, is_batch, run_batch_command
    from rig.commands.formatting import board_line, hints_line, summary_line, warning_text
    from rig.service import AnalysisRequest, analyse
    from rig.service.batch import find_videos
    from rig.service.bench_profile import read_profile, with_profile

    videos = find_videos(args.videos)
    how = config_from_args(AnalysisOptions, args, AnalysisError)
    if args.bench is not None:
        how = with_profile(how, read_profile(args.bench), args.bench)
    request = AnalysisRequest(videos[0], how, board=args.board, tracks_csv=args.csv)
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
        hints = hints_line(result)
        if hints is not None:
            print(hints)
        for name, estimate in result.methods.items():
            if name != result.method:
                ci = f" (95% {estimate.ci95_ms[0]:.2f} to {estimate.ci95_ms[1]:.2f})" if estimate.ci95_ms else ""
                print(f"  {name}: {estimate.latency_ms:.2f} ms{ci}")
        for warning in result.warnings:
            print(warning_text(warning))
    if args.plot is not None:
        from analysis.plots import plot_tracks

        writes = outputs.LateWrites()
        writes.write(args.plot, lambda: plot_tracks(result, args.plot))
        writes.check()
    return EXIT_WARNINGS if result.warnings else 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "analyse",
        description="Track the LED and the rendered sphere and measure by how much the sphere lags. "
        "Without ROIs the two moving blobs are found and told apart by physical evidence (the display's refresh "
        "steps, the LED's saturation, size, side); when that does not decide, the command stops and asks for the "
        "ROIs. The interval allows for the camera's sampling of the display and for model misfit. Exit status: 0 "
        "clean, 3 measured with warnings (read them), 2 user error. Compiled fits are kept between runs "
        "(JAX_COMPILATION_CACHE_DIR chooses the folder).",
        listings=methods_listing,
    )
    parser.add_argument(
        "videos",
        type=Path,
        nargs="+",
        metavar="VIDEO",
        help="video file (mp4, avi, mov, mkv), folder of numbered images, folder of videos, or glob; "
        "more than one makes a batch",
    )
    add_declared_options(parser, AnalysisOptions)
    parser.add_argument(
        "--bench",
        type=Path,
        metavar="FILE.toml",
        help="the bench profile (`rig plan --bench`, `rig calibrate-camera --bench`): its display, exposure, readout, "
        "LED side and regions are used where the options above do not give them, each checked against the video "
        "(a contradiction is a warning naming both)",
    )
    parser.add_argument(
        "--board",
        type=Path,
        metavar="DIR",
        help="a `rig board record --blink` folder made while filming: the LED's blink code puts the video on the "
        "board's clock and the encoder's start of swing fixes the whole number of periods",
    )
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
