"""`rig bench SUBJECT`: benchmarks that print a table and write JSON and a plot of speed against error.

The subjects are the modules of `rig.bench`, each registered here with its options (SUBJECTS).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

import predictors
from predictors import read_trace
from rig.bench import analyser, batch
from rig.bench import predictors as predictor_bench
from rig.commands import choices, options, outputs
from rig.commands.bench_camera_calibration import add_camera_calibration
from rig.commands.bench_live import add_live
from rig.commands.bench_renderers import add_renderers
from rig.errors import ConfigError
from rig.progress import ProgressBar
from rig.service.sweep import read_sweep


def _log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


# -- analyser ------------------------------------------------------------------------------------


def _run_analyser(args: argparse.Namespace) -> int:
    sweep = read_sweep(analyser.QUICK_SPEC if args.quick else args.spec)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rig-bench-analyser-") as scratch:
        folder = args.runs if args.runs is not None else Path(scratch)
        report = analyser.run_bench(sweep, folder, _log, args.workers, args.scheduler, analyser.GROUPS[args.grid])
    report["seconds"] = time.perf_counter() - started
    writes = outputs.LateWrites()
    if args.json is not None:
        writes.json(args.json, report)
    if args.plot is not None:
        writes.write(args.plot, lambda: analyser.plot(report["summary"], report["cases"], args.plot))
    for group, summary in report["summaries"].items():
        print(f"{group} ({summary['sinefit']['cases']} cases):")
        print(analyser.table(summary))
    for target, met in report["targets_met"].items():
        print(f"{target}: {'met' if met else 'not met' if met is not None else 'n/a'}")
    print(f"{len(report['cases'])} cases in {report['seconds'] / 60:.1f} minutes")
    writes.check()
    return 0


def _add_analyser(benchmarks: argparse._SubParsersAction) -> None:
    parser = benchmarks.add_parser(
        "analyser",
        help="error, interval coverage, confidently wrong answers and speed of each latency estimator on simulated videos",
        description="Simulate videos of known latency over two grids, analyse each with every method, and report "
        "per method the median and worst error, the coverage of the 95 % intervals, the confidently wrong answers "
        "(truth outside the interval by more than max(0.5 ms, its half-width)), the refusals and the speed against "
        "decoding alone. The mixed grid spans periods, frame rates, refresh rates, swings, damping and "
        "impairments; the hard grid, what goes wrong in a lab: camera rates that lock to the display's, short "
        "exposures, a dim LED or sphere, swapped sides, a second bright object, a partly hidden blob, decimated "
        "films. Both take about forty minutes on two cores; --quick runs three tiny cases. The cases are a sweep "
        f"spec ({analyser.SPEC.name}, in {analyser.SPECS}): `rig sweep` on it gives the same summary rows; "
        "--spec runs the bench on an edited copy.",
    )
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the summaries, every case and the sweep's rows as JSON")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="plot speed against error per method")
    cases = parser.add_mutually_exclusive_group()
    cases.add_argument("--spec", type=Path, default=analyser.SPEC, metavar="SPEC.toml",
                       help="the cases, as a sweep whose points are labelled case, group (mixed, named or hard) and "
                       "impairment (default: the bench's own)")  # fmt: skip
    cases.add_argument("--quick", action="store_true", help=f"three short cases (a smoke test; {analyser.QUICK_SPEC.name})")
    parser.add_argument("--grid", choices=tuple(analyser.GROUPS), default="all", help="which grid to run, by the points' group (default: %(default)s)")
    parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR",
                        help="keep the simulated videos and the sweep's summary.csv here (default: a temporary folder)")  # fmt: skip
    options.add_executor_options(parser, "the grid")
    parser.set_defaults(func=_run_analyser)


# -- predictors ----------------------------------------------------------------------------------


def _horizons_ms(text: str) -> tuple[float, ...]:
    """A comma-separated list of horizons in ms, each >= 0."""
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected horizons in ms separated by commas, got {text!r}") from None
    if not all(math.isfinite(v) and v >= 0.0 for v in values):
        raise argparse.ArgumentTypeError(f"horizons must be zero or positive milliseconds, got {text!r}")
    return values


def _run_predictors(args: argparse.Namespace) -> int:
    horizons = args.horizons_ms
    if args.plot_horizon_ms not in horizons:
        raise ConfigError(f"--plot-horizon-ms {args.plot_horizon_ms:g} must be one of --horizons-ms {','.join(f'{h:g}' for h in horizons)}")
    traces = [read_trace(path) for path in args.trace or []]
    if args.stress:
        traces += predictor_bench.stress_traces(args.duration, args.seed)
    if not traces:
        traces = predictor_bench.default_traces(args.duration, args.seed)
    specs = args.predictor or [(name, {}) for name in predictors.names()]
    if (predictor_bench.BASELINE, {}) not in specs:
        specs = [*specs, (predictor_bench.BASELINE, {})]
    results = predictor_bench.run_bench(traces, specs, horizons, args.timing_repeats, ProgressBar("benchmarking predictors"))
    print(predictor_bench.table(results, horizons))
    ratios = predictor_bench.ratios(results, horizons)
    shown = [h for h in horizons if h > 0.0] or list(horizons)
    print(f"\nangular RMS error / constant velocity ({predictor_bench.BASELINE}) at {' / '.join(f'{h:g}' for h in shown)} ms:")
    print(predictor_bench.ratio_table(ratios, "angular", shown))
    if any(math.isfinite(v) for entry in ratios for by_horizon in entry.position.values() for v in by_horizon.values()):
        print(f"\nposition RMS error / constant velocity at {' / '.join(f'{h:g}' for h in shown)} ms (traces with position):")
        print(predictor_bench.ratio_table(ratios, "position", shown))
    costs = predictor_bench.cost_ratios(results)
    for trace, ratio in costs.items():
        print(f"kalman-cv / desp cost on {trace}: {ratio:.2f}")
    held = []
    for name in args.leave_one_out or []:
        if len(traces) < 2:
            raise ConfigError("--leave-one-out needs at least two traces: it tunes on all but one")
        held += predictor_bench.leave_one_out(
            name, traces, args.plot_horizon_ms, args.tune_iterations, ProgressBar(f"tuning {name}, each trace held out in turn")
        )
    if held:
        print(f"\nleave one trace out: tuned at {args.plot_horizon_ms:g} ms on the others, RMS error / constant velocity on the one held out:")
        print(predictor_bench.held_out_table(held))
    writes = outputs.LateWrites()
    if args.json:
        writes.json(args.json, {
            "horizons_ms": list(horizons),
            "baseline": predictor_bench.BASELINE,
            "kalman_cv_over_desp_cost": costs,
            "ratios": [entry.to_dict(horizons) for entry in ratios],
            "leave_one_out": [h.to_dict() for h in held],
            "results": [r.to_dict() for r in results],
        })
    if args.plot:
        writes.write(args.plot, lambda: predictor_bench.plot(results, args.plot_horizon_ms, args.plot))
    writes.check()
    return 0


def _tunable(name: str) -> str:
    from predictors.tuning import TUNABLE  # imports JAX: only when the option is given

    if name not in TUNABLE:
        raise argparse.ArgumentTypeError(f"cannot tune {name!r}; tunable predictors: {', '.join(TUNABLE)}")
    return name


def _add_predictors(benchmarks: argparse._SubParsersAction) -> None:
    parser = benchmarks.add_parser(
        "predictors",
        help="score every predictor on traces: error against constant velocity at several horizons, and cost per update",
        description=predictor_bench.__doc__.split("\n\n")[0] + " With no --trace or --stress, runs the simulated "
        "pendulum, the synthetic head and the two recordings in data/traces.",
        epilog=choices.predictors_listing(),
    )
    parser.add_argument("--trace", type=Path, action="append", metavar="FILE",
                        help="trace CSV (t_sensor,t_arrival,px,py,pz,qw,qx,qy,qz, or t instead of t_sensor); repeat "
                        "for several (default: the built-in four)")  # fmt: skip
    parser.add_argument("--stress", action="store_true",
                        help="run the synthetic stress streams (30-1000 Hz, noise, jitter, repeats, sudden stops) too")  # fmt: skip
    parser.add_argument("--predictor", type=options.predictor_spec, action="append", metavar="NAME[:key=value,...]",
                        help="predictor (listed below) and parameters, or NAME:FILE.json; repeat for several (default: every "
                        f"predictor); {predictor_bench.BASELINE}, the baseline, is always run")  # fmt: skip
    parser.add_argument("--horizons-ms", type=_horizons_ms, default=predictor_bench.DEFAULT_HORIZONS_MS, metavar="H,H,...",
                        help="prediction horizons after each sample's arrival (default: 0,10,20,50,100)")  # fmt: skip
    parser.add_argument("--plot-horizon-ms", type=options.non_negative_float, default=50.0,
                        help="the horizon the plot shows and --leave-one-out tunes for (default: %(default)s)")  # fmt: skip
    parser.add_argument("--leave-one-out", type=_tunable, action="append", metavar="NAME",
                        help="tune NAME on all traces but one and score it on that one, for each trace; repeat for several")  # fmt: skip
    parser.add_argument("--tune-iterations", type=options.non_negative_int, default=40,
                        help="optimiser iterations per --leave-one-out fit (default: %(default)s)")  # fmt: skip
    parser.add_argument("--duration", type=options.positive_float, default=30.0,
                        help="seconds of simulated pendulum, synthetic head and stress streams (default: %(default)s)")  # fmt: skip
    parser.add_argument("--seed", type=int, default=0, help="seed of the simulated traces (default: %(default)s)")
    parser.add_argument("--timing-repeats", type=options.non_negative_int, default=3,
                        help="timed replays per predictor and trace; the best counts (default: %(default)s)")  # fmt: skip
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write every score, ratio and held-out result as JSON")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="draw speed against error")
    parser.set_defaults(func=_run_predictors)


# -- batch ---------------------------------------------------------------------------------------


def _run_batch(args: argparse.Namespace) -> int:
    with tempfile.TemporaryDirectory(prefix="rig-bench-batch-") as scratch:
        report = batch.run_bench(Path(scratch), args.videos, args.duration, args.clip_duration, args.workers, args.rounds, _log)
    writes = outputs.LateWrites()
    if args.json is not None:
        writes.json(args.json, report)
    if args.plot is not None:
        writes.write(args.plot, lambda: batch.plot(report, args.plot))
    print(batch.table(report))
    writes.check()
    return 0


def _add_batch(benchmarks: argparse._SubParsersAction) -> None:
    parser = benchmarks.add_parser(
        "batch",
        help="what many measurements cost: a batch serially and on Dask, and the fixed cost per video",
        description=batch.__doc__.split("\n\n")[0],
    )
    parser.add_argument("--videos", type=options.positive_int, default=24, help="videos in the batch (default: %(default)s)")
    parser.add_argument("--duration", type=options.positive_float, default=6.0, help="seconds per batch video (default: %(default)s)")
    parser.add_argument("--clip-duration", type=options.positive_float, default=20.0, help="seconds of the fixed-cost clip (default: %(default)s)")
    parser.add_argument("--workers", type=options.positive_int, default=2, help="Dask worker processes (default: %(default)s)")
    parser.add_argument("--rounds", type=options.positive_int, default=3,
                        help="times the batch runs serially and on Dask, alternately (default: %(default)s)")  # fmt: skip
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the figures as JSON")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="draw the wall times")
    parser.set_defaults(func=_run_batch)


# -- trackers ------------------------------------------------------------------------------------


def _run_trackers(args: argparse.Namespace) -> int:
    from rig.bench import trackers

    duration = 2.0 if args.quick else args.duration
    with tempfile.TemporaryDirectory(prefix="rig-bench-trackers-") as scratch:
        folder = args.runs if args.runs is not None else Path(scratch)
        report = trackers.run_bench(args.rate, duration, folder, _log)
    writes = outputs.LateWrites()
    if args.json is not None:
        writes.json(args.json, report["rows"])
    if args.plot is not None:
        writes.write(args.plot, lambda: trackers.plot(report["rows"], args.plot))
    print(trackers.table(report["rows"]))
    for target, met in report["targets_met"].items():
        print(f"{target}: {'met' if met else 'not met'}")
    loads = [row["load_average_1min"] for row in report["rows"]]
    stolen = [row["stolen_cpu_pct"] for row in report["rows"] if row["stolen_cpu_pct"] is not None]
    print(f"machine noise: {os.cpu_count()} CPUs, 1-minute load average {min(loads):.2f} to {max(loads):.2f} over the cases"
          + (f", CPU stolen by the virtual machine's host {min(stolen):.1f} to {max(stolen):.1f} %" if stolen else ""))  # fmt: skip
    writes.check()
    return 0


def _add_trackers(benchmarks: argparse._SubParsersAction) -> None:
    parser = benchmarks.add_parser(
        "trackers",
        help="the serial and LSL tracker sources fed by the emulators: loss, fabrication, CPU per sample, added latency",
        description="Stream the simulated pendulum from `rig emulate-tracker` (a pseudo-terminal, TCP, LSL), clean and "
        "with faults (1%% of bytes corrupted and a 0.5 s disconnect; a disconnect for LSL), record each with the rig's "
        "tracker source as `rig record-tracker` does, and report per case what was sent, recorded, missing, fabricated "
        "and counted corrupt, the CPU per sample, and the latency from the emulator's write to the sample's queueing for a predictor.",
    )
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the rows as a JSON list")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="plot CPU per sample and latency per case")
    parser.add_argument("--rate", type=options.positive_float, default=1000.0, help="records a second (default: %(default)s)")
    parser.add_argument("--duration", type=options.positive_float, default=10.0, help="seconds per case (default: %(default)s)")
    parser.add_argument("--quick", action="store_true", help="2 s per case (a smoke test)")
    parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR", help="keep the recordings and emulator logs here (default: a temporary folder)")
    parser.set_defaults(func=_run_trackers)


SUBJECTS: dict[str, Callable[[argparse._SubParsersAction], None]] = {
    "analyser": _add_analyser,
    "predictors": _add_predictors,
    "renderers": add_renderers,
    "trackers": _add_trackers,
    "batch": _add_batch,
    "live": add_live,
    "camera-calibration": add_camera_calibration,
}


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="benchmarks: speed against error, as JSON and a plot",
        description="Benchmarks are commands, not tests: each prints a table and writes JSON and a PNG.",
    )
    benchmarks = parser.add_subparsers(dest="bench", required=True, metavar="SUBJECT")
    for add in SUBJECTS.values():
        add(benchmarks)
