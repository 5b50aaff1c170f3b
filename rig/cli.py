"""The `rig` command line. Every user error ends in one line on stderr and exit status 2."""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

from analysis.errors import AnalysisError
from predictors import PredictorError
from rig.commands import analyse, bench, board, demo, report, simulate, sweep, tune
from rig.commands import devices, emulate, record_tracker
from rig.compile_cache import keep_compiled_fits
from rig.errors import RigError

USER_ERRORS = (RigError, PredictorError, AnalysisError)
EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="rig",
        description="Measure motion-to-photon latency with a pendulum, an LED and a camera; simulate the rig.",
    )
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in (demo, simulate, analyse, sweep, report, bench, tune, board, record_tracker, devices, emulate):
        command.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except USER_ERRORS as error:
        print(f"rig {args.command}: error: {error}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print(f"\nrig {args.command}: interrupted; everything recorded so far is on disk", file=sys.stderr)
        return EXIT_INTERRUPTED


def run() -> None:
    """Console-script entry point."""
    keep_compiled_fits()
    sys.exit(main())


if __name__ == "__main__":
    run()
