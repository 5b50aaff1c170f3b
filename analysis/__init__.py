"""Video to latency: blob tracking, phase, correlation, fit and posterior estimators, reports.

``analyse(video)`` tracks the pendulum's LED and the rendered sphere, and measures by how much the
sphere lags the LED; ``write_tracks_csv`` saves the tracks it used. JAX is imported only when a
fit (sinefit, bayes) is asked for.
"""

from analysis.errors import AnalysisError
from analysis.pipeline import analyse
from analysis.report import write_tracks_csv
from analysis.result import METHODS, LatencyResult, MethodResult

__all__ = ["METHODS", "AnalysisError", "LatencyResult", "MethodResult", "analyse", "write_tracks_csv"]
