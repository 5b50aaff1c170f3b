"""Video to latency: blob tracking, phase and fit estimators, reports.

``analyse(video)`` tracks the pendulum's LED and the rendered sphere, and measures by how much the
sphere lags the LED (Steed's phase method); ``write_tracks_csv`` saves the tracks it used.
"""

from analysis.errors import AnalysisError
from analysis.pipeline import analyse
from analysis.report import write_tracks_csv
from analysis.result import LatencyResult

__all__ = ["AnalysisError", "LatencyResult", "analyse", "write_tracks_csv"]
