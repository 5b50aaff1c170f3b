"""`rig demo`: simulate the default rig, measure its latency from the video, compare with the truth."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from analysis.plots import plot_tracks
from rig.commands import simulate
from rig.commands.analyse import run_analysis, summary_line
from rig.errors import RigError

AGREEMENT_MS = 1.0
EXIT_MISMATCH = 1


def _run(args: argparse.Namespace) -> int:
    out: Path = args.out
    config = simulate.config_from_args(args)
    if not args.json:
        print(
            f"simulating {config.duration_s:g} s: {config.display.refresh_hz:g} Hz display, "
            f"{config.tracker.rate_hz:g} Hz tracker, predictor {config.predictor}, renderer {config.renderer}, "
            f"{config.camera.fps:g} fps camera -> {out}"
        )
    # A demo folder holds synthetic data only: rerunning the demo replaces a previous simulation
    # (recognised by its truth.json) but never anything else.
    sim = simulate.run_simulation(config, out, overwrite=(out / "truth.json").exists())
    result = run_analysis(sim.video_path)
    true_ms = sim.truth["latency_ms"]
    difference = result.latency_ms - true_ms
    agrees = abs(difference) <= AGREEMENT_MS and not result.ambiguous
    plot_path = out / "demo.png"
    try:
        plot_tracks(result, plot_path, title=f"rig demo: measured {result.latency_ms:.2f} ms, true {true_ms:.2f} ms")
    except OSError as error:
        raise RigError(f"cannot write the plot {plot_path}: {error}") from error
    if args.json:
        print(
            json.dumps(
                {
                    "latency_true_ms": true_ms,
                    "latency_measured_ms": result.latency_ms,
                    "difference_ms": difference,
                    "agrees": agrees,
                    "analysis": result.to_dict(),
                    "simulation": simulate.summary(sim),
                    "plot": str(plot_path),
                }
            )
        )
    else:
        verdict = "OK" if agrees else "MISMATCH"
        print(f"true latency      {true_ms:8.2f} ms  (truth.json: what an ideal analyser measures)")
        print(f"measured latency  {result.latency_ms:8.2f} ms  ({summary_line(result)})")
        print(f"difference        {difference:+8.2f} ms  {verdict}: the analyser should agree within {AGREEMENT_MS:g} ms")
        print(f"plot of both trajectories: {plot_path}")
        for warning in result.warnings:
            print(f"warning: {warning}")
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
    simulate.add_simulation_options(parser)
    parser.set_defaults(func=_run)
