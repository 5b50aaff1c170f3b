"""Pose prediction: pose types, quaternion maths, the predictors that hide latency, and their scoring.

    from predictors import Pose, PoseSample, make

    predictor = make("kalman-cv")
    predictor.update(PoseSample(t_sensor=0.0, t_arrival=0.002, position=p, orientation=q))
    pose = predictor.predict(0.016)

Predictors (`names()`): hold, slerp, kalman-cv, kalman-ca, desp, auto, adaptive, split, rls; each class
documents its parameters and their units. `make(DEFAULT)` ("default") makes the one to use when none is
named: `rls`, which learns on the stream it is fed how to weigh the angular velocity and its moving
averages at each horizon, and predicts position as `adaptive` does. `evaluate` scores one on a `Trace` (`read_trace` reads CSV files);
`SAMPLE_COLUMNS`, `sample_row` and `read_samples` are the one file format of tracker samples.
`predictors.quaternion` holds the vectorised quaternion maths, (w, x, y, z) Hamilton;
`predictors.corpus` reads a folder of recordings labelled by device, person and scene and
`predictors.cross_validation` scores choices by group, each scored on a group it was not chosen on;
`predictors.synthetic` generates head motion and `predictors.stress` the stress streams (rates,
noise, faults, sudden stops) a default predictor must survive. Tuning (`predictors.tuning`) and the JAX twins of the
filters (`predictors.jax_filters`) import JAX, so they are imported only by name, never from here:
the real-time path stays free of it.
"""

from typing import TYPE_CHECKING

from declared.lazy import lazy_exports

if TYPE_CHECKING:  # the names as documentation tools and type checkers read them
    from predictors.errors import PredictorError
    from predictors.evaluation import Evaluation, HorizonScore, evaluate
    from predictors.params_file import read_params, write_params
    from predictors.pose import Pose, PoseSample
    from predictors.registry import DEFAULT, Predictor, make, names, resolve
    from predictors.trace import SAMPLE_COLUMNS, Trace, read_samples, read_trace, sample_row, write_trace


__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "quaternion": "predictors.quaternion",
        "PredictorError": "predictors.errors",
        "Evaluation": "predictors.evaluation",
        "HorizonScore": "predictors.evaluation",
        "evaluate": "predictors.evaluation",
        "read_params": "predictors.params_file",
        "write_params": "predictors.params_file",
        "Pose": "predictors.pose",
        "PoseSample": "predictors.pose",
        "DEFAULT": "predictors.registry",
        "Predictor": "predictors.registry",
        "make": "predictors.registry",
        "names": "predictors.registry",
        "resolve": "predictors.registry",
        "SAMPLE_COLUMNS": "predictors.trace",
        "Trace": "predictors.trace",
        "read_samples": "predictors.trace",
        "read_trace": "predictors.trace",
        "sample_row": "predictors.trace",
        "write_trace": "predictors.trace",
    },
)

__all__ = [
    "DEFAULT",
    "SAMPLE_COLUMNS",
    "Evaluation",
    "HorizonScore",
    "Pose",
    "PoseSample",
    "Predictor",
    "PredictorError",
    "Trace",
    "evaluate",
    "make",
    "names",
    "quaternion",
    "read_params",
    "read_samples",
    "read_trace",
    "resolve",
    "sample_row",
    "write_params",
    "write_trace",
]
