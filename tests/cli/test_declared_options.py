"""Options made from declared settings (`rig.commands.declared_options`): --help lists each with its
unit and default, a value is read back into the config in the setting's unit, and a value outside
the range is refused while the command line is read, naming the option and the range."""

from __future__ import annotations

import argparse
import re

import pytest

from analysis import AnalysisError, AnalysisOptions
from analysis.shutter import ShutterOptions
from declared import walk
from rig.cli import main
from rig.commands.declared_options import add_declared_options, config_from_args

DECLARED = {"analyse": AnalysisOptions, "calibrate-camera": ShutterOptions}


def _help(capsys: pytest.CaptureFixture[str], command: str) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = capsys.readouterr().out
    return " ".join(text[text.index("\n\n") :].split())  # after the usage lines


@pytest.mark.parametrize("command", DECLARED)
def test_help_lists_every_declared_option_with_its_unit_and_default(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, command)
    for entry in walk(DECLARED[command]):
        flag = entry.setting.flag
        if flag is None:
            continue
        described = text[text.index(f"{flag.name} ") :]
        described = described[: described.find(" --", 1)]
        unit = flag.unit if flag.unit is not None else entry.setting.unit
        assert " ".join(entry.setting.help.split()) in described, flag.name
        if unit:
            assert f"({unit};" in described or f"({unit})" in described, flag.name
        if entry.hint is not bool:
            assert re.search(r"default: \S", described), flag.name


def _parsed(kind: type, *argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_declared_options(parser, kind)
    return parser.parse_args(argv)


def test_the_options_given_make_the_config_and_the_rest_keep_their_defaults() -> None:
    args = _parsed(AnalysisOptions, "--latency-range=-50,300", "--display-hz", "90", "--led-roi", "1,2,30,40", "--sphere-roi", "50,2,30,40")
    assert config_from_args(AnalysisOptions, args, AnalysisError) == AnalysisOptions(
        latency_range_ms=(-50.0, 300.0), display_hz=90.0, led_roi=(1, 2, 30, 40), sphere_roi=(50, 2, 30, 40)
    )
    assert config_from_args(AnalysisOptions, _parsed(AnalysisOptions), AnalysisError) == AnalysisOptions()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--display-hz", "0"], "argument --display-hz: must be a positive number of Hz, got 0"),
        (["--seed", "-1"], "argument --seed: must be zero or a positive whole number, got -1"),
        (["--seed", "1.5"], "argument --seed: expected a whole number, got '1.5'"),
        (["--led-roi=-1,0,10,10"], "argument --led-roi: must have each item zero or a positive whole number of pixels, got -1,0,10,10"),
        (["--led-roi", "1,2,3"], "argument --led-roi: expected X,Y,W,H, 4 whole numbers, got '1,2,3'"),
        (["--latency-range", "50,1"], "argument --latency-range: LOW must be below HIGH, got 50,1"),
    ],
)
def test_a_value_outside_its_setting_is_refused_naming_the_option(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        _parsed(AnalysisOptions, *argv)
    assert message in capsys.readouterr().err
