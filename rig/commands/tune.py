"""`rig tune`: fit a predictor's parameters to recorded motion and report held-out error.

Training traces are the --trace files; held-out traces are the --held-out files, or, without any,
the last part of each training trace (--split says how much is kept for training). The fitted
parameters go to --out as a file that `rig simulate --predictor NAME:FILE.json`, `rig bench
predictors --predictor NAME:FILE.json` and `predictors.make(name, **predictors.read_params(FILE)[1])`
accept.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from predictors import evaluate, read_trace, write_params
from rig.commands import options


def _held_out_rms(name: str, params: dict, traces: list, horizon_s: float) -> dict[str, float]:
    """Angular (deg) and position (mm) RMS error over the held-out traces, weighted by count."""
    scores = [evaluate(name, trace, [horizon_s], params, timing_repeats=1).scores[0] for trace in traces]
    count = sum(s.count for s in scores)
    angular = (sum(s.count * s.angular_rms_deg**2 for s in scores) / count) ** 0.5
    position = (sum(s.count * s.position_rms_mm**2 for s in scores) / count) ** 0.5
    return {"angular_rms_deg": angular, "position_rms_mm": position}


def _run(args: argparse.Namespace) -> int:
    from predictors.tuning import tune  # imports JAX: only when tuning

    traces = [read_trace(path) for path in args.trace]
    if args.held_out:
        train, held_out = traces, [read_trace(path) for path in args.held_out]
    else:
        halves = [trace.split(args.split) for trace in traces]
        train, held_out = [h[0] for h in halves], [h[1] for h in halves]
    horizon_s = args.horizon_ms / 1e3
    name, start = args.predictor
    print(f"tuning {name} at {args.horizon_ms:g} ms on {sum(len(t) for t in train)} samples ...", flush=True)
    result = tune(name, train, horizon_s, start, max_iterations=args.max_iterations)
    fitted = ", ".join(f"{k}={result.params[k]:.6g}" for k in result.fitted) or "nothing (no motion to fit)"
    print(f"fitted {fitted}; training loss {result.loss_before:.4g} -> {result.loss_after:.4g} "
          f"in {result.iterations} iterations")
    comparison = {
        f"{name} tuned": _held_out_rms(name, result.params, held_out, horizon_s),
        f"{name} start": _held_out_rms(name, start, held_out, horizon_s),
        "slerp": _held_out_rms("slerp", {}, held_out, horizon_s),
    }
    print(f"held-out RMS error at {args.horizon_ms:g} ms ({sum(len(t) for t in held_out)} samples):")
    for label, rms in comparison.items():
        print(f"  {label:24s} {rms['angular_rms_deg']:.4f} deg  {rms['position_rms_mm']:.4f} mm")
    write_params(
        args.out,
        name,
        result.params,
        horizon_ms=args.horizon_ms,
        fitted=list(result.fitted),
        train=[t.name for t in train],
        held_out={"traces": [t.name for t in held_out], **comparison},
    )
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
