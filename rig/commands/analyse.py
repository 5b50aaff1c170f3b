"""`rig analyse VIDEO`: measure the latency between the LED and the rendered sphere in a video."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import analysis
from analysis import LatencyResult
from rig.commands import options
from rig.progress import ProgressBar


def summary_line(result: LatencyResult) -> str:
    """The one line a lab reads."""
    ci = f" (95% CI {result.ci95_ms[0]:.2f} to {result.ci95_ms[1]:.2f} ms)" if result.ci95_ms else ""
    flag = " AMBIGUOUS" if result.ambiguous else ""
    return (
        f"latency {result.latency_ms:.2f} ms{ci}{flag} by {result.method}, swing period {result.period_s:.4f} s, "
        f"{result.frames_used}/{result.frames} frames used"
    )


def run_analysis(
    video: Path,
    fps: float | None = None,
    led_roi: tuple[int, int, int, int] | None = None,
    sphere_roi: tuple[int, int, int, int] | None = None,
) -> LatencyResult:
    return analysis.analyse(video, fps=fps, led_roi=led_roi, sphere_roi=sphere_roi, progress=ProgressBar("analysing"))


def _run(args: argparse.Namespace) -> int:
    result = run_analysis(args.video, args.fps, args.led_roi, args.sphere_roi)
    if args.csv is not None:
        analysis.write_tracks_csv(args.csv, result)
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        print(summary_line(result))
        for warning in result.warnings:
            print(f"warning: {warning}")
    return 0


def add_analysis_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--led-roi", type=options.roi, metavar="X,Y,W,H", help="region the LED swings in (pixels)")
    parser.add_argument("--sphere-roi", type=options.roi, metavar="X,Y,W,H", help="region the sphere moves in (pixels)")
    parser.add_argument("--fps", type=options.positive_float, help="camera frame rate, overriding the file's")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "analyse",
        help="measure latency from a video of the LED and the sphere",
        description="Track the LED and the rendered sphere and measure by how much the sphere lags "
        "(Steed's phase method). Without ROIs the two moving blobs are found and the brighter is the LED.",
    )
    parser.add_argument("video", type=Path, help="video file")
    add_analysis_options(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--csv", type=Path, metavar="FILE", help="write both tracks as CSV")
    parser.set_defaults(func=_run)
