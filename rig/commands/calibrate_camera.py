"""`rig calibrate-camera FILM --flash-hz F`: a camera's readout and exposure from a film of a flashing light.

Exits 0 for a clean result, 3 (`rig.cli.EXIT_WARNINGS`) for one with warnings, 2 when the film
cannot decide (the one line says what to change).
"""

from __future__ import annotations

import argparse
import json
import sys
from datetime import date
from pathlib import Path
from typing import TYPE_CHECKING

from analysis.errors import AnalysisError
from analysis.shutter.options import DISPLAY_GROUP, ShutterOptions
from rig.cli import EXIT_WARNINGS
from rig.commands import outputs
from rig.commands.declared_options import add_declared_options, config_from_args, declared_type
from rig.progress import ProgressBar
from rig.sim.flash_target import FlashTarget

if TYPE_CHECKING:
    from analysis.shutter import ShutterResult


def _run(args: argparse.Namespace) -> int:
    from rig.service import CalibrationRequest, calibrate_camera
    from rig.service.bench_profile import read_profile, shutter_display, write_profile
    from rig.service.calibrate import bench_changes

    if args.bench is not None and args.bench.exists():
        profile = read_profile(args.bench)
        if args.source == "display" and args.display_hz is None:
            vars(args).update(shutter_display(profile))
    options = config_from_args(ShutterOptions, args, AnalysisError)
    result = calibrate_camera(CalibrationRequest(args.film, args.flash_hz, options), ProgressBar("reading the film"))
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        print("\n".join(result_lines(result)))
    if args.bench is not None:
        write_profile(args.bench, bench_changes(result, args.film, date.today().isoformat()))
        line = f"bench profile {args.bench}: wrote the camera's readout, exposure and frame rate" + (
            " (the calibration came with warnings: read them)" if result.warnings else ""
        )
        print(line, file=sys.stderr if args.json else sys.stdout)
    return EXIT_WARNINGS if result.warnings else 0


def result_lines(result: ShutterResult) -> list[str]:
    """The readout, the exposure and what the film showed, a line each, then the warnings."""
    from rig.commands.formatting import warning_text

    low, high = (v * 1e3 for v in result.readout_ci95_s)
    if result.global_shutter:
        readout = f"readout 0 ms: a global shutter (95% at most {high:.3f} ms)"
    else:
        readout = (
            f"readout {result.readout_s * 1e3:.3f} ms (95% {low:.3f} to {high:.3f}), rows read {result.readout_direction}, "
            f"{result.line_time_s * 1e6:.3f} us a row over {result.frame_height}"
        )
    e_low, e_high = (v * 1e3 for v in result.exposure_ci95_s)
    bands = (
        "no bands: whole frames go light and dark"
        if result.ramp_rows is None
        else f"bands {result.band_periods:.2f} flash periods across the rows, ramps {result.ramp_rows:.1f} rows long"
    )
    source = "the light" if result.source == "light" else "the display"
    return [
        readout,
        f"exposure {result.exposure_s * 1e3:.3f} ms (95% {e_low:.3f} to {e_high:.3f})",
        f"film: {result.frames} frames at {result.fps:.3f} fps ({result.timing_source}); {source} flashing at "
        f"{result.flash_hz_seen:.4g} Hz (given {result.flash_hz:g}), on {result.duty:.1%} of each period, over rows "
        f"{result.rows[0]}-{result.rows[1]} ({result.row_count} used, {result.saturated_pixels} saturated pixels left out); "
        f"{bands}; frames agree with the bands to {result.timing_rms_s * 1e3:.3f} ms; misfit {result.misfit:.1%} of the swing",
        *(warning_text(warning) for warning in result.warnings),
    ]


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "calibrate-camera",
        description="Film a light flashing at a known frequency (an LED lighting a white card, or out of focus so "
        "that it fills the view), or a display flashing full-field, for a few seconds; this measures the "
        "camera's rolling-shutter readout (0 for a global shutter) and its exposure from the bands the flash "
        "draws, each with its 95 % interval. Choose the flash frequency so that the exposure is shorter than "
        "half the time the light is on and off; with a 50 % duty cycle, also so that a period less the "
        "exposure is longer than the frame interval (or give --max-exposure-ms); and so that it is no simple "
        "fraction of the frame rate. Exit status: 0 clean, 3 with warnings, 2 when the film cannot decide "
        "(the message says what to change).",
    )
    parser.add_argument("film", type=Path, metavar="FILM", help="video file (mp4, avi, mov, mkv) or folder of numbered images")
    parser.add_argument("--flash-hz", type=declared_type(FlashTarget, "hz"), required=True, metavar="F", help="the light's flash frequency (Hz)")
    add_declared_options(parser, ShutterOptions, {"display": DISPLAY_GROUP})
    parser.add_argument(
        "--bench",
        type=outputs.output_file(".toml"),
        metavar="FILE.toml",
        help="write the readout, exposure and frame rate measured, with their 95%% intervals, into this bench profile "
        "(made if there is none; what else it holds is kept); a flashing display without --display-hz takes its "
        "refresh and scan-out from it",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object, times in seconds")
    parser.set_defaults(func=_run)
