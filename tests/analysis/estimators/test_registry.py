"""The estimator registry: built-in estimators in their order, and one registered from outside the package."""

import pytest

from analysis import (
    AnalysisError,
    AnalysisOptions,
    EstimationContext,
    MethodResult,
    analyse,
    estimate,
    methods,
    register_estimator,
    track,
    unregister_estimator,
)
from analysis.estimators.sinefit import joint_fit

BUILT_IN = ("fft", "xcorr", "sinefit", "bayes")


class FitCentre:
    """An estimator of a lab's own: the joint fit's latency without its interval, reusing the fit
    sinefit computes when both run (and computing it when alone)."""

    name = "fit-centre"
    gives_interval = False

    def estimate(self, context: EstimationContext) -> MethodResult:
        fit = context.shared(joint_fit)
        return MethodResult(self.name, fit.latency_s * 1e3, None, fit.model, 0.0, {"periods": context.cycles.how}, fit)


@pytest.fixture
def fit_centre():
    estimator = FitCentre()
    register_estimator(estimator)
    yield estimator
    unregister_estimator(estimator.name)


def test_the_built_in_estimators_run_in_their_order():
    assert methods() == BUILT_IN


def test_an_estimator_registered_from_outside_runs_by_its_name_and_with_all(fit_centre, scene, render_video):
    clip = scene(latency_s=0.04, duration_s=4.1, fps=120.0)
    frames = render_video(clip)
    assert methods() == (*BUILT_IN, "fit-centre")
    alone = analyse(frames, AnalysisOptions(fps=clip.fps, method="fit-centre"))
    assert alone.method == "fit-centre" and list(alone.methods) == ["fit-centre"]
    assert alone.latency_ms == pytest.approx(40.0, abs=0.3)
    assert alone.ci95_ms is None
    assert alone.to_dict()["methods"]["fit-centre"]["periods"] == alone.cycles.how
    everything = estimate(track(frames, AnalysisOptions(fps=clip.fps)), AnalysisOptions(method="all"))
    assert list(everything.methods) == [*BUILT_IN, "fit-centre"]
    assert everything.method == "sinefit"
    # The fit is computed once and shared: the outside estimator got sinefit's own.
    assert everything.methods["fit-centre"].fit is everything.methods["sinefit"].fit
    assert everything.methods["fit-centre"].latency_ms == everything.methods["sinefit"].latency_ms == alone.latency_ms


def test_an_unregistered_estimator_is_gone(scene, render_video):
    register_estimator(FitCentre())
    unregister_estimator("fit-centre")
    assert methods() == BUILT_IN
    with pytest.raises(AnalysisError, match="method must be one of fft, xcorr, sinefit, bayes, all, got 'fit-centre'"):
        analyse(render_video(scene(duration_s=2.5, fps=120.0)), AnalysisOptions(fps=120.0, method="fit-centre"))


def test_a_taken_name_or_a_broken_estimator_is_refused(fit_centre):
    with pytest.raises(ValueError, match="already registered"):
        register_estimator(FitCentre())
    with pytest.raises(ValueError, match="already registered"):
        register_estimator(type("Fft", (FitCentre,), {"name": "fft"})())
    with pytest.raises(ValueError, match="needs a name other than 'all'"):
        register_estimator(type("All", (FitCentre,), {"name": "all"})())
    with pytest.raises(ValueError, match="gives_interval"):
        register_estimator(type("Unsure", (FitCentre,), {"name": "unsure", "gives_interval": None})())
    with pytest.raises(ValueError, match="no estimator named 'nothing'"):
        unregister_estimator("nothing")
    assert methods() == (*BUILT_IN, "fit-centre")
