"""The predictor bench (`rig bench predictors`): every predictor on every trace, its error against
constant velocity and against its cost. With no --trace or --stress, it runs the simulated
pendulum, the synthetic head and the two recordings in data/traces.

Declared here, without the bench's libraries, for the command line; `rig.bench.predictors` runs it.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path

from declared import Flag, Range, setting
from rig.bench.contract import Command, bench_in
from rig.commands import choices, options
from rig.commands.declared_options import add_declared_options
from rig.tune_settings import HORIZONS

BASELINE = "slerp"
"""The predictor every other is scored against: constant velocity from the two newest samples."""
DEFAULT_HORIZONS_MS = (0.0, 10.0, 20.0, 50.0, 100.0)


@dataclass(frozen=True)
class PredictorBenchOptions:
    """The predictor bench's numeric options, each declared on its field (the command line's are
    made from them and checked against their ranges as they are read)."""

    horizons_ms: tuple[float, ...] = setting(
        DEFAULT_HORIZONS_MS, "ms", "prediction horizons after each sample's arrival", HORIZONS,
        flag=Flag("--horizons-ms", metavar="H,H,..."),
    )  # fmt: skip
    plot_horizon_ms: float = setting(50.0, "ms", "the horizon the plot shows and --leave-one-out tunes for", HORIZONS,
                                     flag="--plot-horizon-ms")  # fmt: skip
    tune_iterations: int = setting(40, "", "optimiser iterations per --leave-one-out fit", Range(0.0, 10000.0, True, True),
                                   flag="--tune-iterations")  # fmt: skip
    duration_s: float = setting(
        30.0, "seconds", "simulated pendulum, synthetic head and stress streams, each (a minute of motion scores a "
        "predictor; ten minutes is the most the bench simulates)", Range(1.0, 600.0, True, True), flag="--duration",
    )  # fmt: skip
    seed: int = setting(0, "", "seed of the simulated traces", Range(0.0, 1e9, True, True), flag="--seed")
    timing_repeats: int = setting(3, "", "timed replays per predictor and trace; the best counts", Range(0.0, 100.0, True, True),
                                  flag="--timing-repeats")  # fmt: skip


def _tunable(name: str) -> str:
    from predictors.tuning import TUNABLE  # imports JAX: only when the option is given

    if name not in TUNABLE:
        raise argparse.ArgumentTypeError(f"cannot tune {name!r}; tunable predictors: {', '.join(TUNABLE)}")
    return name


def _options(parser: argparse.ArgumentParser) -> None:
    parser.epilog = choices.predictors_listing()
    parser.add_argument("--trace", type=Path, action="append", metavar="FILE",
                        help="trace CSV (t_sensor,t_arrival,px,py,pz,qw,qx,qy,qz, or t instead of t_sensor); repeat "
                        "for several (default: the built-in four)")  # fmt: skip
    parser.add_argument("--repair", action="store_true",
                        help="sort a --trace that is out of time order and drop repeated times, instead of refusing it")  # fmt: skip
    parser.add_argument("--stress", action="store_true",
                        help="run the synthetic stress streams (30-1000 Hz, noise, jitter, repeats, sudden stops) too")  # fmt: skip
    parser.add_argument("--predictor", type=options.predictor_spec, action="append", metavar="NAME[:key=value,...]",
                        help="predictor (listed below) and parameters, or NAME:FILE.json; repeat for several (default: every "
                        f"predictor); {BASELINE}, the baseline, is always run")  # fmt: skip
    parser.add_argument("--corpus", type=Path, metavar="DIR",
                        help="score on a corpus of recordings instead, by recording and by device, person and scene "
                        "(labels from the file names or DIR/manifest.csv; see docs/predictor-validation.md)")  # fmt: skip
    parser.add_argument("--manifest", type=Path, metavar="FILE",
                        help="with --corpus: the recordings' labels (CSV file,device,person,scene,apart) instead of DIR/manifest.csv")  # fmt: skip
    parser.add_argument("--cross-validate", action="store_true",
                        help="with --corpus: choose among the predictors on all groups but one and score the choice on "
                        "that one, for every person, scene and device")  # fmt: skip
    parser.add_argument("--headroom", action="store_true",
                        help="with --corpus: fit linear predictors on the default's features on all groups but one, with "
                        "every future sample known, and score them on that one: how far that family could go")  # fmt: skip
    parser.add_argument("--leave-one-out", type=_tunable, action="append", metavar="NAME",
                        help="tune NAME on all traces but one and score it on that one, for each trace; repeat for several")  # fmt: skip
    add_declared_options(parser, PredictorBenchOptions)


SUBJECT = Command(
    name="predictors",
    help="score every predictor on traces: error against constant velocity at several horizons, and cost per update",
    bench=bench_in("predictors"),
    options=_options,
    outputs={"json": "write every score, ratio and held-out result as JSON", "plot": "draw speed against error"},
)
