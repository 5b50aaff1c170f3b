"""`rig demo`: simulate the default rig, measure its latency from the video, compare with the truth.

`rig demo --compare` runs one heavy scene through the direct and the warp renderer and prints both
measured latencies side by side.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from rig.commands import outputs
from rig.commands.simulation_options import add_simulation_options, simulation_config
from rig.demo_settings import AGREEMENT_MS, COMPARE_APP_FRAME_MS, COMPARE_RENDERERS, COMPARE_TRIANGLES
from rig.progress import ProgressBar

if TYPE_CHECKING:
    from rig.sim.config import SimulationConfig

EXIT_MISMATCH = 1


def _run(args: argparse.Namespace) -> int:
    from rig.commands.formatting import summary_line, warning_text
    from rig.service import comparison_config, demo

    config = simulation_config(args)
    if args.compare:
        return _run_comparison(args, comparison_config(config))
    out: Path = args.out
    if not args.json:
        print(
            f"simulating {config.duration_s:g} s: {config.display.refresh_hz:g} Hz display, "
            f"{config.tracker.rate_hz:g} Hz tracker, predictor {config.predictor}, renderer {config.renderer}, "
            f"{config.camera.fps:g} fps camera -> {out}"
        )
    report = demo(config, out, ProgressBar)
    if args.json:
        print(json.dumps(report.to_dict()))
    else:
        result = report.measurement.result
        verdict = "OK" if report.agrees else "MISMATCH"
        print(f"true latency      {report.true_ms:8.2f} ms  (truth.json: what an ideal analyser measures)")
        print(f"measured latency  {report.measured_ms:8.2f} ms  ({summary_line(result)})")
        print(f"difference        {report.difference_ms:+8.2f} ms  {verdict}: the analyser should agree within {AGREEMENT_MS:g} ms")
        print(f"plot of both trajectories: {report.plot}")
        for warning in result.warnings:
            print(warning_text(warning))
    return 0 if report.agrees else EXIT_MISMATCH


def _cost_text(ms: float | None, what: str) -> str:
    return f"{what} measured on this machine" if ms is None else f"{what} {ms:g} ms (modelled)"


def _run_comparison(args: argparse.Namespace, config: SimulationConfig) -> int:
    from rig.commands.formatting import warning_text
    from rig.service import compare_renderers

    if not args.json:
        print(
            f"comparing {' and '.join(COMPARE_RENDERERS)} on one scene: {config.scene_triangles} load triangles, "
            f"{_cost_text(config.app_frame_ms, 'application frame')}, "
            f"{_cost_text(config.warp_ms, 'warp per refresh')}; "
            f"{config.duration_s:g} s at {config.display.refresh_hz:g} Hz, predictor {config.predictor} -> {args.out}/<renderer>"
        )
    reports = compare_renderers(config, args.out, ProgressBar)
    agrees = all(report.agrees for report in reports.values())
    if args.json:
        print(json.dumps({name: report.to_dict() for name, report in reports.items()}))
    else:
        print(f"{'renderer':10} {'true latency':>14} {'measured latency':>18} {'difference':>12}")
        for name, report in reports.items():
            verdict = "OK" if report.agrees else "MISMATCH"
            print(
                f"{name:10} {report.true_ms:11.2f} ms {report.measured_ms:15.2f} ms "
                f"{report.difference_ms:+9.2f} ms  {verdict}"
            )
            for warning in report.measurement.result.warnings:
                print(warning_text(warning, f"warning ({name})"))
        print(f"plots: {', '.join(str(report.plot) for report in reports.values())}")
    return 0 if agrees else EXIT_MISMATCH


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        description="Simulate the default rig (pendulum, tracker, predictor, OpenGL renderer, display, camera), "
        "analyse the video it writes, and print the measured latency beside the true one. "
        f"Exits with {EXIT_MISMATCH} if they differ by more than {AGREEMENT_MS:g} ms.",
    )
    parser.add_argument("--out", type=outputs.output_folder, default="out/demo", metavar="DIR", help="output folder (default: %(default)s)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--compare",
        action="store_true",
        help=f"run one heavy scene through the {' and the '.join(COMPARE_RENDERERS)} renderer (into DIR/<renderer>) "
        f"and print both latencies side by side; a scene left at the defaults becomes {COMPARE_TRIANGLES} load "
        f"triangles at {COMPARE_APP_FRAME_MS:g} ms (modelled) per application frame",
    )
    add_simulation_options(parser)
    parser.set_defaults(func=_run)
