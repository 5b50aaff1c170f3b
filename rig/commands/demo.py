"""`rig demo`: simulate the default rig, measure its latency from the video, compare with the truth.

`rig demo --compare` runs one heavy scene through the direct and the warp renderer and prints both
measured latencies side by side.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path
from typing import Any

from analysis import LatencyResult
from analysis.plots import plot_tracks
from rig.commands import simulate
from rig.commands.analyse import run_analysis, summary_line
from rig.errors import RigError
from rig.session import DEFAULT_WARP_MS, SimulationConfig

AGREEMENT_MS = 1.0
EXIT_MISMATCH = 1
COMPARE_RENDERERS = ("direct", "warp")
COMPARE_TRIANGLES = 100_000
COMPARE_APP_FRAME_MS = 100.0


def _measure(config: SimulationConfig, out: Path) -> tuple[dict[str, Any], LatencyResult]:
    """Simulate `config` into `out`, analyse the video, plot both trajectories: the report and the
    analysis."""
    # A demo folder holds synthetic data only: rerunning the demo replaces a previous simulation
    # (recognised by its truth.json) but never anything else.
    sim = simulate.run_simulation(config, out, overwrite=(out / "truth.json").exists())
    result = run_analysis(sim.video_path)
    true_ms = sim.truth["latency_ms"]
    difference = result.latency_ms - true_ms
    plot_path = out / "demo.png"
    try:
        plot_tracks(result, plot_path, title=f"rig demo: measured {result.latency_ms:.2f} ms, true {true_ms:.2f} ms")
    except OSError as error:
        raise RigError(f"cannot write the plot {plot_path}: {error}") from error
    report = {
        "latency_true_ms": true_ms,
        "latency_measured_ms": result.latency_ms,
        "difference_ms": difference,
        "agrees": abs(difference) <= AGREEMENT_MS and not result.ambiguous,
        "analysis": result.to_dict(),
        "simulation": simulate.summary(sim),
        "plot": str(plot_path),
    }
    return report, result


def _config(args: argparse.Namespace) -> SimulationConfig:
    """The simulated rig the options describe; for --compare, a scene left at the defaults (no load,
    cheap frames) becomes the heavy one."""
    config = simulate.config_from_args(args)
    defaults = SimulationConfig()
    if args.compare and config.scene_triangles == defaults.scene_triangles:
        config = replace(config, scene_triangles=COMPARE_TRIANGLES)
    if args.compare and config.app_frame_ms == defaults.app_frame_ms:
        config = replace(config, app_frame_ms=COMPARE_APP_FRAME_MS)
    return config


def _run(args: argparse.Namespace) -> int:
    config = _config(args)
    if args.compare:
        return _run_comparison(args, config)
    out: Path = args.out
    if not args.json:
        print(
            f"simulating {config.duration_s:g} s: {config.display.refresh_hz:g} Hz display, "
            f"{config.tracker.rate_hz:g} Hz tracker, predictor {config.predictor}, renderer {config.renderer}, "
            f"{config.camera.fps:g} fps camera -> {out}"
        )
    report, result = _measure(config, out)
    if args.json:
        print(json.dumps(report))
    else:
        verdict = "OK" if report["agrees"] else "MISMATCH"
        print(f"true latency      {report['latency_true_ms']:8.2f} ms  (truth.json: what an ideal analyser measures)")
        print(f"measured latency  {result.latency_ms:8.2f} ms  ({summary_line(result)})")
        print(f"difference        {report['difference_ms']:+8.2f} ms  {verdict}: the analyser should agree within {AGREEMENT_MS:g} ms")
        print(f"plot of both trajectories: {report['plot']}")
        for warning in result.warnings:
            print(f"warning: {warning}")
    return 0 if report["agrees"] else EXIT_MISMATCH


def _cost_text(ms: float | None, what: str) -> str:
    return f"{what} measured on this machine" if ms is None else f"{what} {ms:g} ms (modelled)"


def _run_comparison(args: argparse.Namespace, config: SimulationConfig) -> int:
    if not args.json:
        print(
            f"comparing {' and '.join(COMPARE_RENDERERS)} on one scene: {config.scene_triangles} load triangles, "
            f"{_cost_text(config.app_frame_ms, 'application frame')}, "
            f"{_cost_text(config.warp_ms if config.warp_ms is not None else DEFAULT_WARP_MS, 'warp per refresh')}; "
            f"{config.duration_s:g} s at {config.display.refresh_hz:g} Hz, predictor {config.predictor} -> {args.out}/<renderer>"
        )
    measured = {name: _measure(replace(config, renderer=name), args.out / name) for name in COMPARE_RENDERERS}
    reports = {name: report for name, (report, _) in measured.items()}
    agrees = all(report["agrees"] for report in reports.values())
    if args.json:
        print(json.dumps(reports))
    else:
        print(f"{'renderer':10} {'true latency':>14} {'measured latency':>18} {'difference':>12}")
        for name, report in reports.items():
            verdict = "OK" if report["agrees"] else "MISMATCH"
            print(
                f"{name:10} {report['latency_true_ms']:11.2f} ms {report['latency_measured_ms']:15.2f} ms "
                f"{report['difference_ms']:+9.2f} ms  {verdict}"
            )
            for warning in measured[name][1].warnings:
                print(f"warning ({name}): {warning}")
        print(f"plots: {', '.join(report['plot'] for report in reports.values())}")
    return 0 if agrees else EXIT_MISMATCH


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="simulate the rig end to end and check the analyser against the known latency",
        description="Simulate the default rig (pendulum, tracker, predictor, OpenGL renderer, display, camera), "
        "analyse the video it writes, and print the measured latency beside the true one. "
        f"Exits with {EXIT_MISMATCH} if they differ by more than {AGREEMENT_MS:g} ms.",
    )
    parser.add_argument("--out", type=Path, default=Path("out/demo"), metavar="DIR", help="output folder (default: %(default)s)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--compare",
        action="store_true",
        help=f"run one heavy scene through the {' and the '.join(COMPARE_RENDERERS)} renderer (into DIR/<renderer>) "
        f"and print both latencies side by side; a scene left at the defaults becomes {COMPARE_TRIANGLES} load "
        f"triangles at {COMPARE_APP_FRAME_MS:g} ms (modelled) per application frame",
    )
    simulate.add_simulation_options(parser)
    parser.set_defaults(func=_run)
