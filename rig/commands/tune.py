"""`rig tune`: fit a predictor's parameters to recorded motion and report held-out error.

Training traces are the --trace files; held-out traces are the --held-out files, or, without any,
the last part of each training trace (--split says how much is kept for training). The fitted
parameters go to --out (see `rig.service.tune`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from predictors import read_trace
from rig.commands import options
from rig.service import split_traces, tune


def _run(args: argparse.Namespace) -> int:
    traces = [read_trace(path) for path in args.trace]
    held_out = [read_trace(path) for path in args.held_out or []]
    train, held_out = split_traces(traces, held_out, args.split)
    name, start = args.predictor
    print(f"tuning {name} at {args.horizon_ms:g} ms on {sum(len(t) for t in train)} samples ...", flush=True)
    report = tune(name, start, train, held_out, args.horizon_ms / 1e3, args.max_iterations)
    fit = report.fit
    fitted = ", ".join(f"{k}={fit.params[k]:.6g}" for k in fit.fitted) or "nothing (no motion to fit)"
    print(f"fitted {fitted}; training loss {fit.loss_before:.4g} -> {fit.loss_after:.4g} in {fit.iterations} iterations")
    print(f"held-out RMS error at {args.horizon_ms:g} ms ({report.held_out_samples} samples):")
    for label, rms in report.comparison.items():
        print(f"  {label:24s} {rms['angular_rms_deg']:.4f} deg  {rms['position_rms_mm']:.4f} mm")
    report.write(args.out, args.horizon_ms)
    print(f"wrote {args.out}")
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `tune`."""
    parser = subparsers.add_parser(
        "tune",
        help="fit a predictor's parameters (Kalman noise ratios and damping, DESP's smoothing, auto's "
        "choice) to recorded motion",
        description=__doc__.split("\n\n")[0] + " Tunable: kalman-cv, kalman-ca, desp, auto.",
    )
    parser.add_argument("predictor", type=options.predictor_spec, metavar="PREDICTOR[:key=value,...]",
                        help="predictor to tune, with starting or fixed parameters (e.g. the tracker's noise)")
    parser.add_argument("--trace", type=Path, action="append", required=True, metavar="FILE",
                        help="training trace CSV; repeat for several")
    parser.add_argument("--held-out", type=Path, action="append", metavar="FILE",
                        help="held-out trace CSV; repeat for several (default: the end of each training trace)")
    parser.add_argument("--split", type=options.positive_float, default=0.6,
                        help="fraction of each trace's duration to train on when no --held-out is given (default: %(default)s)")
    parser.add_argument("--horizon-ms", type=options.non_negative_float, required=True,
                        help="prediction horizon after each sample's arrival to tune for")
    parser.add_argument("--max-iterations", type=options.non_negative_int, default=40,
                        help="optimiser iterations at most (default: %(default)s)")
    parser.add_argument("--out", type=Path, required=True, metavar="FILE.json", help="parameter file to write")
    parser.set_defaults(func=_run)
