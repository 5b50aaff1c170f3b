"""`rig bench analyser --quick`: the whole benchmark on two tiny simulated videos."""

import argparse
import json
from pathlib import Path

import pytest

from rig.bench import analyser
from rig.commands import bench


@pytest.fixture
def parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rig")
    bench.add_parser(parser.add_subparsers())
    return parser


def test_quick_bench_reports_every_method_with_errors_coverage_and_speed(
    parser: argparse.ArgumentParser, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, plot = tmp_path / "bench.json", tmp_path / "bench.png"
    args = parser.parse_args(["bench", "analyser", "--quick", "--json", str(out), "--plot", str(plot)])
    assert args.func(args) == 0
    report = json.loads(out.read_text())
    assert set(report["summary"]) == {"fft", "xcorr", "sinefit", "bayes"}
    assert len(report["cases"]) == 2
    for case in report["cases"]:
        frame_ms = 1e3 / case["camera_fps"]
        for method, row in case["methods"].items():
            assert abs(row["error_frames"]) < 0.5, (case["case"], method)
            assert row["error_ms"] == pytest.approx(row["error_frames"] * frame_ms)
            assert row["seconds"] > 0 and row["speed_ratio"] > 0
        assert case["methods"]["sinefit"]["covered"] in (True, False)
        assert case["methods"]["fft"]["covered"] is None
    sinefit = report["summary"]["sinefit"]
    assert sinefit["unambiguous"] == 2 and sinefit["intervals"] == 2
    assert set(report["targets_met"]) >= {"sinefit_median_le_0.1_frames", "sinefit_speed_ge_0.8_of_decoding"}
    assert plot.stat().st_size > 10_000
    table = capsys.readouterr().out
    assert "| sinefit |" in table and "| bayes |" in table


def test_grid_covers_every_axis_value_and_the_hard_cases() -> None:
    cases = analyser.grid(24)
    configs = [case.config for case in cases[:24]]
    assert {c.pendulum.period_s for c in configs} == set(analyser.PERIODS_S)
    assert {c.camera.fps for c in configs} == set(analyser.CAMERA_FPS)
    assert {c.display.refresh_hz for c in configs} == set(analyser.DISPLAY_HZ)
    assert {c.pendulum.amplitude_deg for c in configs} == set(analyser.AMPLITUDES_DEG)
    assert {c.pendulum.quality for c in configs} == set(analyser.QUALITIES)
    assert {case.impairment for case in cases[:24]} == set(analyser.IMPAIRMENTS)
    beyond_half = [case for case in cases if case.target_ms > case.config.pendulum.period_s * 500]
    assert beyond_half
    assert any(case.config.pendulum.release_s is not None for case in beyond_half)
    assert all(c.camera.fps * c.camera.subsamples >= analyser.SUBSAMPLE_RATE for c in configs)
    assert analyser.grid(24) == cases
