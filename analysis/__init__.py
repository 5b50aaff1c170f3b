"""Video to latency: blob tracking, phase, correlation, fit and posterior estimators, reports.

``analyse(video, AnalysisOptions(...))`` tracks the pendulum's LED and the rendered sphere, and
measures by how much the sphere lags the LED. It is two parts, which can be called alone, each
taking the same options: ``track(video, options) -> Tracks`` (read, calibrate, track, time and
check) and ``estimate(tracks, options) -> LatencyResult`` (the free swing, the whole number of
periods, the estimators). ``AnalysisOptions`` declares every option once (``analysis.options``);
its ``hints`` carry what a lab says of its bench (``Hint``), each checked against the video
(``analysis.hints``).
``Tracks.write_csv`` saves tracks; the estimators are listed by ``methods()``, and
``register_estimator`` adds one (see ``analysis.estimators``). JAX is imported only when a fit
(sinefit, bayes) is asked for, and no import changes a JAX setting.
"""

from typing import TYPE_CHECKING

from declared.lazy import lazy_exports

if TYPE_CHECKING:  # the names as documentation tools and type checkers read them
    from analysis.errors import AnalysisError
    from analysis.estimation import estimate
    from analysis.estimators.contract import EstimationContext, Estimator
    from analysis.estimators.registry import methods, register_estimator, unregister_estimator
    from analysis.hints import Hint
    from analysis.options import AnalysisOptions
    from analysis.pipeline import analyse
    from analysis.result import LatencyResult, MethodResult
    from analysis.tracks import Tracks, track


__getattr__, __dir__ = lazy_exports(
    __name__,
    {
        "AnalysisError": "analysis.errors",
        "estimate": "analysis.estimation",
        "EstimationContext": "analysis.estimators.contract",
        "Estimator": "analysis.estimators.contract",
        "methods": "analysis.estimators.registry",
        "register_estimator": "analysis.estimators.registry",
        "unregister_estimator": "analysis.estimators.registry",
        "Hint": "analysis.hints",
        "AnalysisOptions": "analysis.options",
        "analyse": "analysis.pipeline",
        "LatencyResult": "analysis.result",
        "MethodResult": "analysis.result",
        "Tracks": "analysis.tracks",
        "track": "analysis.tracks",
    },
)

__all__ = [
    "AnalysisError",
    "AnalysisOptions",
    "EstimationContext",
    "Estimator",
    "Hint",
    "LatencyResult",
    "MethodResult",
    "Tracks",
    "analyse",
    "estimate",
    "methods",
    "register_estimator",
    "track",
    "unregister_estimator",
]
