"""`rig simulate`: run the simulated rig and write video, samples, frame logs and ground truth."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

from rig.commands import outputs
from rig.commands.simulation_options import add_flash_options, add_simulation_options, simulation_config
from rig.progress import ProgressBar
from rig.session.run_files import BOARD_FOLDER

if TYPE_CHECKING:
    from rig.sim.config import SimulationConfig


def _run(args: argparse.Namespace) -> int:
    from rig.service import simulate
    from rig.service.run_plot import plot_run

    config = simulation_config(args)
    result = simulate(config, args.out, ProgressBar("simulating"), args.overwrite)
    writes = outputs.LateWrites()
    if args.plot is not None:
        writes.write(args.plot, lambda: plot_run(result.out_dir, result.truth.latency_ms, args.plot))
    if args.json:
        print(json.dumps(result.summary()))
    elif config.flash is not None:
        print(f"wrote {result.truth.frames} frames of {flash_line(config)} to {result.video_path}")
    else:
        truth = result.truth
        d = truth.display_frame_delay_ms
        print(
            f"wrote {truth.frames} frames to {result.video_path}; true latency "
            f"{truth.latency_ms:.2f} ms (sensor-to-photon delay per display frame "
            f"{d.mean:.2f} +/- {d.sd:.2f} ms)"
        )
        print(result.cost_line())
        if args.plot is not None and not writes.failed:
            print(f"plot of the tracked, predicted and displayed sphere and the delay per refresh: {args.plot}")
    writes.check()
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "simulate",
        description="Simulate pendulum, tracker, predictor, renderer, display and camera on a virtual clock. "
        "Writes DIR/video.avi, DIR/camera_frames.csv, DIR/truth.json, DIR/tracker.csv, DIR/app_frames.csv and "
        "DIR/display_frames.csv, "
        f"and with --board the board's recording in DIR/{BOARD_FOLDER}/.",
    )
    parser.add_argument("--out", type=outputs.output_folder, required=True, metavar="DIR", help="output folder")
    parser.add_argument("--overwrite", action="store_true", help="replace a run already in DIR")
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    parser.add_argument(
        "--plot",
        type=outputs.plot_file,
        metavar="FILE.png",
        help="plot the run's truth: the sphere as tracked, predicted and displayed, and each refresh's delay from "
        "the newest sample to its photons beside the true latency",
    )
    add_simulation_options(parser, lab=True)
    add_flash_options(parser)
    parser.set_defaults(func=_run)


def flash_line(config: SimulationConfig) -> str:
    """What a calibration film shows and the shutter that filmed it, in one line."""
    flash, camera = config.flash, config.camera
    assert flash is not None
    if flash.source == "light":
        shown = f"a light flashing at {flash.hz:g} Hz ({flash.duty:.0%} on)"
    else:
        shown = f"the display flashing at {config.display.refresh_hz / flash.refreshes:g} Hz ({flash.display_duty():.0%} white)"
    return f"{shown}, filmed with a {camera.readout_s * 1e3:g} ms readout and a {camera.exposure * 1e3:g} ms exposure"
