"""Pose prediction: pose types, quaternion maths and the predictors that hide latency.

    from predictors import Pose, PoseSample, make

    predictor = make("slerp")
    predictor.update(PoseSample(t_sensor=0.0, t_arrival=0.002, position=p, orientation=q))
    pose = predictor.predict(0.016)

`predictors.quaternion` holds the vectorised quaternion maths, (w, x, y, z) Hamilton.
"""

from predictors import quaternion
from predictors.errors import PredictorError
from predictors.pose import Pose, PoseSample
from predictors.registry import Predictor, make, names

__all__ = ["Pose", "PoseSample", "Predictor", "PredictorError", "make", "names", "quaternion"]
