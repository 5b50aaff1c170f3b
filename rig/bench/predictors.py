"""`rig bench predictors`: every predictor on every trace, speed against error.

Default traces:

* `pendulum`: the simulated rig's pendulum and tracker (120 Hz, 4 ms transport delay with jitter,
  0.2 mm and 0.05 deg noise), scored against the exact pendulum motion;
* `synthetic-head`: `predictors.synthetic.head_motion` at 120 Hz with 0.5 mm and 0.1 deg noise,
  scored against the clean motion;
* `hmd_orientation_user1`: a real head-mounted display's orientation at about 60 Hz
  (`data/traces/`, with its licence), scored against itself.

Horizons count from each sample's arrival at the host. Prints a table of RMS errors and
microseconds per update (update plus one predict), and writes JSON and a PNG of speed against
error if asked.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import predictors
from predictors import Evaluation, Trace, evaluate, read_trace
from predictors.synthetic import head_motion
from rig.commands import options
from rig.errors import ConfigError
from rig.progress import ProgressBar
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import TrackerConfig, simulate_tracker

REAL_TRACE = Path(__file__).resolve().parents[2] / "data" / "traces" / "hmd_orientation_user1.csv"
DEFAULT_HORIZONS_MS = (0.0, 10.0, 20.0, 50.0, 100.0)
_TRUTH_RATE_HZ = 1000.0


def pendulum_trace(duration_s: float, seed: int) -> Trace:
    """The simulated tracker on the default pendulum, with the exact motion as truth."""
    pendulum = Pendulum(PendulumConfig(), t_end=duration_s + 1.0)
    truth_t = np.arange(int(duration_s * _TRUTH_RATE_HZ) + 1) / _TRUTH_RATE_HZ
    truth = Trace.from_samples("pendulum", truth_t, *pendulum.sensor_pose(truth_t))
    samples = simulate_tracker(pendulum, TrackerConfig(), 0.0, duration_s, seed)
    return truth.with_samples(
        np.array([s.t_sensor for s in samples]),
        np.array([s.t_arrival for s in samples]),
        np.array([s.position for s in samples]),
        np.array([s.orientation for s in samples]),
    )


def default_traces(duration_s: float, seed: int) -> list[Trace]:
    """The pendulum, the synthetic head and the real head-motion trace."""
    head = head_motion(duration_s, 120.0, seed).with_noise(0.0005, math.radians(0.1), seed)
    return [pendulum_trace(duration_s, seed), head, read_trace(REAL_TRACE)]


def horizons_ms(text: str) -> tuple[float, ...]:
    """A comma-separated list of horizons in ms, each >= 0."""
    try:
        values = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected horizons in ms separated by commas, got {text!r}") from None
    if not all(math.isfinite(v) and v >= 0.0 for v in values):
        raise argparse.ArgumentTypeError(f"horizons must be zero or positive milliseconds, got {text!r}")
    return values


def table(results: Sequence[Evaluation], horizons: Sequence[float]) -> str:
    """A Markdown table: per trace and predictor, us/update and RMS errors (mm, deg) per horizon."""
    head = "| trace | predictor | us/update | " + " | ".join(f"{h:g} ms: mm, deg" for h in horizons) + " |"
    rule = "|" + "---|" * (3 + len(horizons))
    rows = [head, rule]
    for result in results:
        cells = [f"{result.at(h).position_rms_mm:.3g}, {result.at(h).angular_rms_deg:.3g}" for h in horizons]
        rows.append(f"| {result.trace} | {result.predictor} | {result.us_per_update:.1f} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def cost_ratios(results: Sequence[Evaluation]) -> dict[str, float]:
    """kalman-cv's us/update over desp's, per trace where both ran."""
    cost = {(r.trace, r.predictor): r.us_per_update for r in results}
    return {
        trace: cost[(trace, "kalman-cv")] / cost[(trace, "desp")]
        for trace, name in cost
        if name == "kalman-cv" and (trace, "desp") in cost
    }


def plot(results: Sequence[Evaluation], horizon_ms: float, path: Path) -> None:
    """Speed against error at one horizon: one column per trace, angle above, position below.

    A trace without position (every predictor's position error zero) gets no position panel.
    """
    from matplotlib.figure import Figure

    traces = list(dict.fromkeys(r.trace for r in results))
    figure = Figure(figsize=(4.5 * len(traces), 7.0))
    axes = figure.subplots(2, len(traces), squeeze=False)
    for column, trace in enumerate(traces):
        of_trace = [r for r in results if r.trace == trace]
        for row, (field, unit) in enumerate((("angular_rms_deg", "deg"), ("position_rms_mm", "mm"))):
            axis = axes[row][column]
            if all(getattr(r.at(horizon_ms), field) == 0.0 for r in of_trace):
                axis.set_axis_off()
                axis.text(0.5, 0.5, f"{trace}: no {'position' if unit == 'mm' else 'orientation'} data", ha="center", transform=axis.transAxes)
                continue
            for result in of_trace:
                error = getattr(result.at(horizon_ms), field)
                axis.scatter(result.us_per_update, error)
                axis.annotate(result.predictor, (result.us_per_update, error), textcoords="offset points", xytext=(4, 4))
            axis.set_xlabel("us per update + predict")
            axis.set_ylabel(f"RMS error at {horizon_ms:g} ms ({unit})")
            axis.set_title(trace if row == 0 else "")
            axis.grid(True, alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=100)


def run_bench(
    traces: Sequence[Trace],
    specs: Sequence[tuple[str, dict[str, Any]]],
    horizons: Sequence[float],
    timing_repeats: int,
    progress: ProgressBar | None = None,
) -> list[Evaluation]:
    """Every predictor spec on every trace."""
    results = []
    total = len(traces) * len(specs)
    for i, trace in enumerate(traces):
        for j, (name, params) in enumerate(specs):
            results.append(evaluate(name, trace, [h / 1e3 for h in horizons], params, timing_repeats))
            if progress is not None:
                progress(i * len(specs) + j + 1, total)
    return results


def _run(args: argparse.Namespace) -> int:
    horizons = args.horizons_ms
    traces = [read_trace(path) for path in args.trace] if args.trace else default_traces(args.duration, args.seed)
    specs = args.predictor or [(name, {}) for name in predictors.names()]
    if args.plot_horizon_ms not in horizons:
        raise ConfigError(f"--plot-horizon-ms {args.plot_horizon_ms:g} must be one of --horizons-ms {','.join(f'{h:g}' for h in horizons)}")
    results = run_bench(traces, specs, horizons, args.timing_repeats, ProgressBar("benchmarking predictors"))
    print(table(results, horizons))
    ratios = cost_ratios(results)
    for trace, ratio in ratios.items():
        print(f"kalman-cv / desp cost on {trace}: {ratio:.2f}")
    if args.json:
        record = {"horizons_ms": list(horizons), "kalman_cv_over_desp_cost": ratios, "results": [r.to_dict() for r in results]}
        args.json.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    if args.plot:
        plot(results, args.plot_horizon_ms, args.plot)
    return 0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    """Register `predictors` (under `rig bench`)."""
    parser = subparsers.add_parser(
        "predictors",
        help="score every predictor on traces: error at several horizons against cost per update",
        description=__doc__.split("\n\n")[0] + " With no --trace, runs the simulated pendulum, the synthetic head "
        "and the real head-motion trace.",
    )
    parser.add_argument("--trace", type=Path, action="append", metavar="FILE",
                        help="trace CSV (t,px,py,pz,qw,qx,qy,qz[,t_arrival]); repeat for several (default: the built-in three)")
    parser.add_argument("--predictor", type=options.predictor_spec, action="append", metavar="NAME[:key=value,...]",
                        help="predictor and parameters, or NAME:FILE.json; repeat for several (default: every predictor)")
    parser.add_argument("--horizons-ms", type=horizons_ms, default=DEFAULT_HORIZONS_MS, metavar="H,H,...",
                        help="prediction horizons after each sample's arrival (default: 0,10,20,50,100)")
    parser.add_argument("--plot-horizon-ms", type=options.non_negative_float, default=50.0,
                        help="the horizon the plot shows (default: %(default)s)")
    parser.add_argument("--duration", type=options.positive_float, default=30.0,
                        help="seconds of simulated pendulum and synthetic head (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the simulated traces (default: %(default)s)")
    parser.add_argument("--timing-repeats", type=options.non_negative_int, default=3,
                        help="timed replays per predictor and trace; the best counts (default: %(default)s)")
    parser.add_argument("--json", type=Path, metavar="OUT", help="write every score as JSON")
    parser.add_argument("--plot", type=Path, metavar="OUT.png", help="draw speed against error")
    parser.set_defaults(func=_run)
