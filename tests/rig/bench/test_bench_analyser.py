"""`rig bench analyser --quick`: the whole benchmark on three tiny simulated videos; the grids."""

import argparse
import json
from pathlib import Path

import pytest

from rig.bench import analyser, analyser_grid
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
    assert set(report["summaries"]) == {"all", "mixed", "hard"}
    assert len(report["cases"]) == 3
    for case in report["cases"]:
        assert not case["refused"]
        frame_ms = 1e3 / case["camera_fps"]
        for method, row in case["methods"].items():
            assert abs(row["error_frames"]) < 0.5, (case["case"], method)
            assert row["error_ms"] == pytest.approx(row["error_frames"] * frame_ms)
            assert row["seconds"] > 0 and row["speed_ratio"] > 0
            assert row["confidently_wrong"] is False
        assert case["methods"]["sinefit"]["covered"] in (True, False)
        assert case["methods"]["fft"]["covered"] is None
    sinefit = report["summary"]["sinefit"]
    assert sinefit["unambiguous"] == 3 and sinefit["intervals"] == 3
    assert sinefit["confidently_wrong"] == 0 and sinefit["refused"] == 0
    assert set(report["targets_met"]) >= {
        "sinefit_median_le_0.1_frames", "sinefit_speed_ge_0.8_of_decoding", "sinefit_no_confidently_wrong",
        "sinefit_unlocked_median_lt_0.05_ms",
    }  # fmt: skip
    assert plot.stat().st_size > 10_000
    table = capsys.readouterr().out
    assert "| sinefit |" in table and "| bayes |" in table and "confidently wrong" in table


def test_grid_covers_every_axis_value_and_the_hard_cases() -> None:
    grid = analyser_grid
    cases = grid.grid(24)
    configs = [case.config for case in cases[:24]]
    assert {c.pendulum.period_s for c in configs} == set(grid.PERIODS_S)
    assert {c.camera.fps for c in configs} == set(grid.CAMERA_FPS)
    assert {c.display.refresh_hz for c in configs} == set(grid.DISPLAY_HZ)
    assert {c.pendulum.amplitude_deg for c in configs} == set(grid.AMPLITUDES_DEG)
    assert {c.pendulum.quality for c in configs} == set(grid.QUALITIES)
    assert {case.impairment for case in cases[:24]} == set(grid.IMPAIRMENTS)
    beyond_half = [case for case in cases if case.target_ms > case.config.pendulum.period_s * 500]
    assert beyond_half
    assert any(case.config.pendulum.release_s is not None for case in beyond_half)
    assert len({c.display.phase for c in configs}) == len(configs)
    assert grid.grid(24) == cases


def test_hard_grid_has_every_rate_pair_exposure_impairment_and_decimation() -> None:
    cases = analyser_grid.hard_grid()
    assert {case.group for case in cases} == {"hard"}
    rates = {(case.config.camera.fps, case.config.display.refresh_hz) for case in cases}
    assert rates >= set(analyser_grid.HARD_RATES)
    fractions = {round(case.config.camera.exposure * case.config.camera.fps, 6) for case in cases}
    assert fractions >= set(analyser_grid.HARD_EXPOSURES)
    assert {case.impairment for case in cases} >= {impairment for impairment, *_ in analyser_grid.HARD_IMPAIRMENTS}
    for fps, every in analyser_grid.DECIMATIONS:
        starts = {case.decimation[1] for case in cases if case.decimation and case.decimation[0] == every}
        assert starts == set(range(every))
    table = [case for case in cases if case.name.startswith("table-")]
    assert [(c.config.camera.fps, c.config.display.refresh_hz, c.config.display.phase) for c in table] == [
        (60.0, 60.0, 0.0), (144.0, 144.0, 0.0)
    ]  # fmt: skip


@pytest.mark.parametrize(
    ("truth", "latency", "ci", "wrong"),
    [
        (42.0, 42.1, (41.9, 42.3), False),
        (42.0, 41.0, (40.8, 41.2), True),  # outside by 0.8 ms, more than 0.5 and the half-width 0.2
        (42.0, 41.6, (41.5, 41.7), False),  # outside by 0.3 ms: less than 0.5 ms
        (42.0, 38.0, (36.5, 39.5), True),  # outside by 2.5 ms, more than the half-width 1.5
        (42.0, 38.0, (35.5, 40.5), False),  # outside by 1.5 ms, less than the half-width 2.5
        (42.0, 42.4, None, False),
        (42.0, 42.6, None, True),
    ],
)
def test_confidently_wrong_is_outside_by_more_than_half_a_millisecond_and_the_half_width(
    truth: float, latency: float, ci: tuple[float, float] | None, wrong: bool
) -> None:
    assert analyser.confidently_wrong(truth, latency, ci) is wrong


def test_cases_that_share_a_film_simulate_it_once_and_rows_keep_the_cases_order(monkeypatch, tmp_path: Path) -> None:
    cases = analyser_grid.quick_grid()
    cases = [cases[0], cases[1], cases[0], cases[2], cases[1]]
    simulated: list[Path] = []
    monkeypatch.setattr(analyser, "simulate", lambda config, folder, overwrite: simulated.append(folder) or config)
    monkeypatch.setattr(analyser, "run_case", lambda case, run, log: {"case": case.name, "film": repr(run), "group": case.group})
    monkeypatch.setattr(analyser, "summarise", lambda rows: {})
    monkeypatch.setattr(analyser, "targets_met", lambda summaries: {})
    report = analyser.run_bench(cases, tmp_path, lambda message: None)
    assert len(simulated) == len({repr(case.config) for case in cases})
    assert [row["case"] for row in report["cases"]] == [case.name for case in cases]
    assert [row["film"] for row in report["cases"]] == [repr(case.config) for case in cases]
