"""--help lists what one can choose, a line each: renderers, predictors, estimators, trackers."""

from __future__ import annotations

import re

import pytest

import analysis
import predictors
from predictors.tuning import TUNABLE
from rig.cli import main
from rig.commands.choices import TRACKER_SPECS, methods_listing
from rig.render import renderer_names


def _help(capsys: pytest.CaptureFixture[str], *command: str) -> str:
    with pytest.raises(SystemExit) as exit_:
        main([*command, "--help"])
    assert exit_.value.code == 0
    return capsys.readouterr().out


def _listed(text: str, name: str) -> bool:
    return re.search(rf"^  {re.escape(name)}  +\S", text, re.MULTILINE) is not None


@pytest.mark.parametrize("command", [["simulate"], ["demo"], ["measure"]])
def test_renderers_and_predictors_are_listed_a_line_each(command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, *command)
    for name in (*renderer_names(), *predictors.names(), predictors.DEFAULT):
        assert _listed(text, name), name


@pytest.mark.parametrize("command", [["record-tracker"], ["measure"]])
def test_tracker_specs_are_listed_a_line_each(command: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, *command)
    for spec in TRACKER_SPECS:
        assert _listed(text, spec), spec


def test_tune_lists_what_it_tunes(capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, "tune")
    assert all(_listed(text, name) for name in TUNABLE)


def test_bench_predictors_lists_every_predictor(capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, "bench", "predictors")
    assert all(_listed(text, name) for name in predictors.names())


def test_analyse_lists_every_estimator(capsys: pytest.CaptureFixture[str]) -> None:
    for text in (methods_listing(), _help(capsys, "analyse")):
        assert all(_listed(text, name) for name in (*analysis.methods(), "all"))


def test_each_listed_line_is_the_first_sentence_of_what_it_lists() -> None:
    from analysis.estimators.registry import estimators_for
    from predictors.tuning import TUNABLE as FITTED
    from rig.commands.choices import DEFAULT_PREDICTOR, METHOD_LINES, PREDICTOR_LINES, RENDERER_LINES, TUNABLE
    from rig.commands.options import first_sentence
    from rig.render.registry import BUILT_IN_RENDERERS

    assert list(PREDICTOR_LINES) == list(predictors.names())
    assert DEFAULT_PREDICTOR == (predictors.DEFAULT, predictors.resolve(predictors.DEFAULT))
    assert TUNABLE == FITTED
    lines = {
        **{name: first_sentence(type(predictors.make(name))) for name in predictors.names()},
        **{name: first_sentence(kind) for name, kind in BUILT_IN_RENDERERS.items()},
        **{name: first_sentence(type(estimators_for(name)[0])) for name in analysis.methods()},
    }
    assert lines == {**PREDICTOR_LINES, **RENDERER_LINES, **METHOD_LINES}


def test_a_built_in_estimator_made_on_first_use_has_its_registered_name() -> None:
    from analysis.estimators.registry import estimators_for

    assert [estimator.name for estimator in estimators_for("all")] == list(analysis.methods())
