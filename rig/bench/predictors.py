"""The predictor bench (`rig bench predictors`): every predictor on every trace, speed against error.

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

import math
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from predictors import Evaluation, Trace, evaluate, read_trace
from predictors.synthetic import head_motion
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
    progress: Callable[[float, float], object] | None = None,
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
