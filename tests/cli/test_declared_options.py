"""Options made from declared settings (`rig.commands.declared_options`): --help lists each with its
unit and default, a value is read back into the config in the setting's unit, and a value outside
the range is refused while the command line is read, naming the option and the range."""

from __future__ import annotations

import argparse
import dataclasses
import re
from pathlib import Path

import pytest

from analysis import AnalysisError, AnalysisOptions
from analysis.shutter import ShutterOptions
from declared import walk
from rig.cli import build_parser, main
from rig.commands.declared_options import add_declared_options, config_from_args
from rig.commands.simulation_options import add_simulation_options, simulation_config
from rig.live.config import EXTERNAL, LiveConfig
from rig.lsl.streams import StreamNames
from rig.sim.board import SimulatedBoardConfig
from rig.sim.camera import CameraConfig
from rig.sim.config import SimulationConfig
from rig.sim.impairments_config import FilmImpairments
from rig.sim.pendulum import PendulumConfig

DECLARED = {"analyse": AnalysisOptions, "simulate": SimulationConfig, "calibrate-camera": ShutterOptions}


def _help(capsys: pytest.CaptureFixture[str], command: str) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = capsys.readouterr().out
    return " ".join(text[text.index("\n\n") :].split())  # after the usage lines


@pytest.mark.parametrize("command", DECLARED)
def test_help_lists_every_declared_option_with_its_unit_and_default(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    text = _help(capsys, command)
    entries = [entry for entry in walk(DECLARED[command]) if entry.setting.flag is not None]
    starts = sorted(text.index(f" {entry.setting.flag.name} ") for entry in entries)
    for entry in entries:
        flag = entry.setting.flag
        start = text.index(f" {flag.name} ")
        described = text[start : next((s for s in starts if s > start), len(text))]
        unit = flag.unit if flag.unit is not None else entry.setting.unit
        assert " ".join((flag.help or entry.setting.help).split()) in described, flag.name
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
        (["--display-hz", "0"], "argument --display-hz: must be a positive number of Hz from 1 to 1000, got 0"),
        (["--seed", "-1"], "argument --seed: must be a whole number from 0 to 1e+09, got -1"),
        (["--seed", "1.5"], "argument --seed: expected a whole number, got '1.5'"),
        (["--led-roi=-1,0,10,10"], "argument --led-roi: must have each item a whole number of pixels from 0 to 65535, got -1,0,10,10"),
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


def _simulation(*argv: str) -> SimulationConfig:
    parser = argparse.ArgumentParser()
    add_simulation_options(parser, lab=True)
    return simulation_config(parser.parse_args(argv))


def test_an_option_in_another_unit_than_its_setting_is_converted_to_the_settings_unit() -> None:
    config = _simulation("--camera-fps", "120", "--exposure", "0.5", "--transport-delay-ms", "2.5", "--app-frame-ms", "measured")
    assert config.camera.exposure_s == 0.5 / 120 and config.tracker.transport_delay_s == 2.5 / 1e3
    assert config.app_frame_ms is None
    assert _simulation().camera.exposure_s == 1.0 / 240 and _simulation().tracker.transport_delay_s == 0.004


def test_the_simulation_options_given_make_the_config_and_the_rest_keep_their_defaults() -> None:
    config = _simulation("--predictor", "kalman-cv:position_noise=0.01", "--board", "--release-s", "2", "--mirrored", "--occluded", "led")
    expected = SimulationConfig(
        pendulum=dataclasses.replace(PendulumConfig(), release_s=2.0), predictor="kalman-cv", predictor_params={"position_noise": 0.01},
        board=SimulatedBoardConfig(), camera=CameraConfig(exposure_s=1.0 / 240, impairments=FilmImpairments(mirrored=True, occluded="led")),
    )  # fmt: skip
    assert config == expected


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--exposure", "1.5"], "argument --exposure: must be a positive number of frame intervals at most 1, got 1.5"),
        (["--transport-delay-ms", "-1"], "argument --transport-delay-ms: must be a number of ms from 0 to 1000, got -1"),
        (["--display-hz", "2000"], "argument --display-hz: must be a positive number of Hz from 1 to 1000, got 2000"),
        (["--release-s=-1"], "argument --release-s: must be a number of seconds from 0 to 3600, got -1"),
        (["--app-frame-ms", "fast"], "argument --app-frame-ms: expected a number or 'measured', got 'fast'"),
        (["--occluded", "lamp"], "argument --occluded: invalid choice: 'lamp'"),
    ],
)
def test_a_simulation_option_outside_its_setting_is_refused_in_the_options_unit(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        _simulation(*argv)
    assert message in capsys.readouterr().err


class _Measured(Exception):
    """Raised in place of a live run, holding the config `rig measure` built."""


def _live_config(monkeypatch: pytest.MonkeyPatch, tmp_path: Path, *argv: str) -> LiveConfig:
    import rig.live.measure

    def stop(config: LiveConfig, *args: object, **kwargs: object) -> None:
        raise _Measured(config)

    monkeypatch.setattr(rig.live.measure, "measure", stop)
    argv = ("measure", "--tracker", "lsl:T", "--camera", "camera:0", "--out", str(tmp_path / "run"), *argv)
    args = build_parser(argv).parse_args(argv)
    with pytest.raises(_Measured) as measured:
        args.func(args)
    return measured.value.args[0]


def test_rig_measure_without_options_runs_the_live_configs_defaults(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    assert _live_config(monkeypatch, tmp_path) == LiveConfig(tracker="lsl:T")


def test_rig_measures_options_make_the_live_config(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    config = _live_config(
        monkeypatch, tmp_path, "--renderer", "direct", "--predictor", "kalman-cv:position_noise=0.01", "--duration", "5",
        "--until-still", "--photon-target", "scanout", "--mirror", "--pose-stream", "P", "--marker-stream", "M",
        "--display", "window?scanout=0.5",
    )  # fmt: skip
    assert config == LiveConfig(
        tracker="lsl:T", renderer="direct", predictor="kalman-cv", predictor_params={"position_noise": 0.01}, duration_s=5.0,
        scanout_fraction=0.5, until_still=True, photon_target="scanout", mirror=True, streams=StreamNames(pose="P", markers="M"),
    )  # fmt: skip


def test_rig_measure_external_and_no_lsl_set_the_renderer_and_the_streams(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    assert _live_config(monkeypatch, tmp_path, "--external", "--renderer", "direct").renderer == EXTERNAL
    assert _live_config(monkeypatch, tmp_path, "--no-lsl", "--pose-stream", "P").streams is None


@pytest.mark.parametrize(("argv", "renderer", "external"), [((), "warp", False), (("--renderer", "direct"), "direct", False),
                                                           (("--external",), "warp", True)])  # fmt: skip
def test_rig_measure_self_test_runs_the_renderer_asked_for(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, argv: tuple[str, ...], renderer: str, external: bool
) -> None:
    import rig.live.selftest.run

    def stop(out_dir: Path, duration_s: float, **kwargs: object) -> None:
        raise _Measured(duration_s, kwargs)

    monkeypatch.setattr(rig.live.selftest.run, "self_test", stop)
    argv = ("measure", "--self-test", "--out", str(tmp_path / "run"), *argv)
    args = build_parser(argv).parse_args(argv)
    with pytest.raises(_Measured) as measured:
        args.func(args)
    duration_s, kwargs = measured.value.args
    assert (duration_s, kwargs["renderer"], kwargs["external"]) == (20.0, renderer, external)
