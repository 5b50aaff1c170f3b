"""`rig sweep SPEC.toml --out DIR`: simulate and analyse every point of a grid, into one summary."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from rig.cli import EXIT_USER_ERROR
from rig.commands import options, outputs
from rig.progress import ProgressBar


def _run(args: argparse.Namespace) -> int:
    from rig.service.sweep import read_sweep, run_sweep

    sweep = read_sweep(args.spec)
    rows, summary = run_sweep(sweep, args.out, args.workers, args.scheduler, ProgressBar("sweeping", unit="points"), args.overwrite)
    if args.json:
        print(json.dumps(rows))
    else:
        labels = sweep.labels
        for row in rows:
            settings = ", ".join(f"{name}={row[name]}" for name in labels if row.get(name) is not None)
            measured = f"{row['latency_ms']:.2f} ms (true {row['truth_ms']:.2f}, error {row['error_ms']:+.3f})" if row["latency_ms"] is not None else f"failed: {row['error']}"
            print(f"{settings}: {measured}")
        print(f"summary: {summary} and {summary.with_suffix('.json')}")
    failed = [row for row in rows if row["status"] == "failed"]
    if rows and len(failed) == len(rows):
        print(f"rig sweep: error: every one of the {len(rows)} points failed (the first: {failed[0]['error']}); "
              f"{summary} says why each did", file=sys.stderr)  # fmt: skip
        return EXIT_USER_ERROR
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "sweep",
        description="SPEC.toml names [base] simulation settings, a [grid] of settings and the values to sweep each "
        "over (every combination runs) and/or [[points]] given one by one (each its settings, and its row's labels "
        "as labels = {...}), and optional [analysis] options (rig analyse's, by their setting names: method, "
        "latency_range_ms, display_hz...; simulated_rois = true to analyse within the regions the simulation put the LED and the sphere in; "
        "bench = \"FILE.toml\" to tell every point a bench profile, or simulated_bench = true to tell each point its own simulated "
        "camera, display and LED side). A cost "
        "(app_frame_ms, warp_ms) may be \"measured\". "
        "Each point is simulated into DIR/pointNNN and analysed; DIR/summary.csv (and .json) gets one row per point "
        "as it finishes, with the truth and the error beside the measured latency. Exit status 2 when every point "
        "failed (the summary says why each did).",
    )
    parser.add_argument("spec", type=Path, metavar="SPEC.toml", help="the sweep")
    parser.add_argument("--out", type=outputs.output_folder, required=True, metavar="DIR", help="folder for the runs and the summary")
    options.add_executor_options(parser, "the points")
    parser.add_argument("--overwrite", action="store_true", help="replace a sweep already in DIR")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    parser.set_defaults(func=_run)
