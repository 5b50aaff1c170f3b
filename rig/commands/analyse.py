"""`rig analyse VIDEO`: measure the latency between the LED and the rendered sphere in a video."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import analysis
from analysis import LatencyResult
from analysis.cycles import DEFAULT_LATENCY_RANGE_S
from analysis.plots import plot_tracks
from analysis.result import DEFAULT_METHOD
from rig.commands import options
from rig.devices.board_reference import EVENT_NAME, BoardReference
from rig.errors import RigError
from rig.progress import ProgressBar


def summary_line(result: LatencyResult) -> str:
    """The one line a lab reads."""
    ci = f" (95% CI {result.ci95_ms[0]:.2f} to {result.ci95_ms[1]:.2f} ms)" if result.ci95_ms else ""
    flag = " AMBIGUOUS" if result.ambiguous else ""
    spread = (
        f", per swing sd {result.windowed.sd_s * 1e3:.2f} ms" if result.windowed is not None and result.windowed.count > 1 else ""
    )
    return (
        f"latency {result.latency_ms:.2f} ms{ci}{flag} by {result.method} ({result.model}), "
        f"swing period {result.period_s:.4f} s{spread}, {result.frames_used}/{result.frames} frames used"
    )


def board_line(board: BoardReference, result: LatencyResult) -> str:
    """What the board recording told: the clock offset, and the start of swing it saw."""
    alignment = board.alignment
    assert alignment is not None
    line = (
        f"board: video on the board's clock by the blink code (offset {alignment.offset_s:.4f} s, "
        f"within {(alignment.high_s - alignment.low_s) * 1e3:.1f} ms, {alignment.agreement:.0%} of frames agree)"
    )
    lag = result.cycles.events_s.get(EVENT_NAME)
    if board.departure_board_s is None:
        return line + "; the encoder did not start from rest while filmed, so it fixed nothing"
    if lag is None:
        return line + "; the sphere's start of swing is not in the video, so the encoder's fixed nothing"
    return line + f"; the sphere left rest {lag * 1e3:.0f} ms after the encoder did"


def run_analysis(
    video: Path,
    fps: float | None = None,
    led_roi: tuple[int, int, int, int] | None = None,
    sphere_roi: tuple[int, int, int, int] | None = None,
    method: str = DEFAULT_METHOD,
    tracks_csv: Path | None = None,
    led_side: str | None = None,
    latency_range_ms: tuple[float, float] = tuple(v * 1e3 for v in DEFAULT_LATENCY_RANGE_S),
    seed: int = 0,
    board: BoardReference | None = None,
) -> LatencyResult:
    """Analyse a video with a progress bar on the terminal; with a board recording, its encoder's
    start of swing (put on the video's clock by the blink code) fixes the whole number of periods."""
    return analysis.analyse(
        video,
        fps=fps,
        led_roi=led_roi,
        sphere_roi=sphere_roi,
        led_side=led_side,
        method=method,
        latency_range_ms=latency_range_ms,
        progress=ProgressBar("analysing"),
        tracks_csv=tracks_csv,
        seed=seed,
        reference_departures=board.departures if board is not None else None,
    )


def _run(args: argparse.Namespace) -> int:
    board = BoardReference.load(args.board) if args.board is not None else None
    result = run_analysis(
        args.video, args.fps, args.led_roi, args.sphere_roi, args.method, args.csv, args.led_side, args.latency_range, args.seed, board
    )
    if args.plot is not None:
        try:
            plot_tracks(result, args.plot)
        except OSError as error:
            raise RigError(f"cannot write the plot {args.plot}: {error}") from error
    if args.json:
        print(json.dumps(result.to_dict() | ({"board": board.to_dict()} if board is not None else {})))
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
    return 0


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
    parser.add_argument("--led-side", choices=("left", "right"), help="the LED is the blob on this side (default: the brighter)")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    low, high = (v * 1e3 for v in DEFAULT_LATENCY_RANGE_S)
    parser = subparsers.add_parser(
        "analyse",
        help="measure latency from a video of the LED and the sphere",
        description="Track the LED and the rendered sphere and measure by how much the sphere lags. "
        "Without ROIs the two moving blobs are found and the brighter is the LED. Methods: fft (Steed's phase "
        "method), xcorr (cross-correlation), sinefit (joint least-squares fit, the default), bayes (posterior "
        "by MCMC), all. Fits compile once per process; set JAX_COMPILATION_CACHE_DIR to keep them between runs.",
    )
    parser.add_argument("video", type=Path, help="video file (mp4, avi, mov, mkv) or folder of numbered images")
    add_analysis_options(parser)
    parser.add_argument("--method", choices=(*analysis.METHODS, "all"), default=DEFAULT_METHOD, help="estimator (default: %(default)s)")
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
    parser.add_argument("--csv", type=Path, metavar="FILE", help="write both tracks as CSV, row by row as they are measured")
    parser.add_argument("--plot", type=Path, metavar="FILE.png", help="plot tracks, fits, residuals and latency over time")
    parser.set_defaults(func=_run)
