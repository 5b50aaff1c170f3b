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
