"""`rig bench SUBJECT`: benchmarks that print a table and write JSON and a plot of speed against error."""

from __future__ import annotations

import argparse
import importlib

SUBJECTS = ("analyser", "predictors", "renderers")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="benchmarks: speed against error, as JSON and a plot",
        description="Benchmarks are commands, not tests: each prints a table and writes JSON and a PNG.",
    )
    benchmarks = parser.add_subparsers(dest="bench", required=True, metavar="SUBJECT")
    for subject in SUBJECTS:
        importlib.import_module(f"rig.bench.{subject}").add_parser(benchmarks)
