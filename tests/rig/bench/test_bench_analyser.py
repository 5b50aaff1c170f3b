"""`rig bench analyser --quick`: the whole benchmark on three tiny simulated videos; its spec (a
sweep), and `rig sweep` on it giving the bench's rows."""

import json
import tomllib
from collections import Counter
from pathlib import Path

import pytest

from rig.bench import analyser, analyser_settings
from rig.bench.contract import Context
from rig.cli import build_parser, main
from rig.service.sweep import SweepPoint, read_sweep
from rig.sim.placement import placement

RIG_BENCH = build_parser(["bench"])
"""`rig`'s command line with its bench command."""


def test_quick_bench_reports_every_method_with_errors_coverage_and_speed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, plot = tmp_path / "bench.json", tmp_path / "bench.png"
    args = RIG_BENCH.parse_args(["bench", "analyser", "--quick", "--json", str(out), "--plot", str(plot)])
    assert args.func(args) == 0
    report = json.loads(out.read_text())
    assert set(report["summary"]) == {"fft", "xcorr", "sinefit", "bayes"}
    assert set(report["summaries"]) == {"all", "mixed", "hard"}
    assert len(report["cases"]) == 3
    assert [row["case"] for row in report["sweep"]] == [case["case"] for case in report["cases"]]
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


def _cases(spec: Path) -> list[SweepPoint]:
    return read_sweep(spec).points(Path("runs"))


def test_the_shipped_spec_parses_into_the_mixed_grid_its_named_cases_and_the_hard_grid() -> None:
    points = _cases(analyser_settings.SPEC)
    groups = [point.labels["group"] for point in points]
    assert groups == ["mixed"] * 48 + ["named"] * 5 + ["hard"] * 58
    assert len({point.labels["case"] for point in points}) == len(points)
    mixed = [point for point in points if point.labels["group"] == "mixed"]
    configs = [point.config for point in mixed]
    assert {c.pendulum.period_s for c in configs} == {0.6, 1.0, 1.4, 1.9}
    assert {c.camera.fps for c in configs} == {60.0, 120.0, 240.0, 480.0}
    assert {c.display.refresh_hz for c in configs} == {60.0, 90.0, 120.0, 144.0}
    assert {c.pendulum.amplitude_deg for c in configs} == {5.0, 20.0, 45.0}
    assert {c.pendulum.quality for c in configs} == {20.0, 100.0, 500.0}
    assert {point.labels["impairment"] for point in mixed} == {"none", "noise", "blur", "dim", "missing"}
    assert len({c.display.phase for c in configs}) == len(configs)
    beyond_half = [p for p in points if float(p.labels["target_ms"]) > p.config.pendulum.period_s * 500]
    assert any(p.config.pendulum.release_s is not None for p in beyond_half)
    film = {p.labels["impairment"]: p.config.camera for p in points}
    assert film["noise"].noise_dn == 8.0 and film["dim"].display_white_dn == 45.0
    assert film["blur"].impairments.blur_sigma_px == 2.5 and film["missing"].impairments.missing_fraction == 0.05


def test_the_hard_grid_has_every_rate_pair_exposure_impairment_and_decimation() -> None:
    hard = [point for point in _cases(analyser_settings.SPEC) if point.labels["group"] == "hard"]
    rates = {(p.config.camera.fps, p.config.display.refresh_hz) for p in hard}
    assert rates >= {(60.0, 60.0), (120.0, 60.0), (60.0, 120.0), (144.0, 144.0), (240.0, 144.0), (59.94, 60.0), (90.0, 60.0), (30.0, 60.0)}
    assert {round(p.config.camera.exposure * p.config.camera.fps, 6) for p in hard} >= {0.05, 0.25, 0.5, 1.0}
    film = {p.labels["impairment"]: p.config.camera.impairments for p in hard}
    assert film["dim-led"].dim_led == 0.35 and film["swapped"].mirrored and film["bright-object"].bright_object_dn == 900.0
    assert film["occluded-sphere"].occluded == "sphere" and film["occluded-led"].occluded == "led"
    decimated = [p.config.camera for p in hard if p.labels["impairment"] == "decimated"]
    phases = {(c.fps, c.impairments.every_nth, c.impairments.first_frame) for c in decimated}
    assert phases == {(240.0, 4, k) for k in range(4)} | {(120.0, 2, k) for k in range(2)}
    assert {c.film_fps for c in decimated} == {60.0}
    table = [p.config for p in hard if p.labels["case"].startswith("table-")]
    assert [(c.camera.fps, c.display.refresh_hz, c.display.phase) for c in table] == [(60.0, 60.0, 0.0), (144.0, 144.0, 0.0)]


ROLLING_SPECS = ("analyser-rolling.toml", "analyser-rolling-told.toml", "analyser-rolling-known.toml")


@pytest.mark.parametrize("spec", [analyser_settings.SPEC, *(analyser_settings.SPECS / name for name in ROLLING_SPECS)])
def test_the_rolling_shutter_films_read_out_within_a_frame_with_the_blobs_a_third_of_the_frame_apart(spec: Path) -> None:
    rolling = [p.config for p in _cases(spec) if p.labels["impairment"] == "rolling-shutter"]
    assert {c.camera.fps for c in rolling} == {30.0, 60.0, 120.0, 240.0}
    assert all(0.0 < c.camera.readout_s <= 1.0 / c.camera.fps for c in rolling)
    for config in rolling:
        led, display = placement(config.layout).led, placement(config.layout).display
        assert 0.30 <= abs(display[1] - led[1]) <= 0.40
    assert len(rolling) == (8 if spec == analyser_settings.SPEC else 40)


def test_the_display_sampling_films_pair_eleven_rates_and_exposures_with_ten_seeds_told_their_bench() -> None:
    spec = analyser_settings.SPECS / "analyser-sampling-told.toml"
    points = _cases(spec)
    assert read_sweep(spec).analysis == {"method": "sinefit", "simulated_bench": True}
    films = Counter((p.config.camera.fps, p.config.display.refresh_hz, round(p.config.camera.exposure * p.config.camera.fps, 3))
                    for p in points)  # fmt: skip
    assert len(films) == 11 and set(films.values()) == {10}
    assert (240.0, 60.0, 0.5) in films and (144.0, 144.0, 0.3) in films
    assert {p.config.seed for p in points} == set(range(10, 20))
    assert all(p.config.camera.readout_s == 0.0 for p in points)


def test_the_specs_are_package_data() -> None:
    pyproject = tomllib.loads((Path(__file__).parents[3] / "pyproject.toml").read_text())
    patterns = pyproject["tool"]["setuptools"]["package-data"]["rig.bench"]
    shipped = {path.name for pattern in patterns for path in Path(analyser.__file__).parent.glob(pattern)}
    assert {analyser_settings.SPEC.name, analyser_settings.QUICK_SPEC.name} <= shipped


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


def test_rig_sweep_on_the_spec_gives_the_rows_of_the_bench(monkeypatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # The first of the quick cases; the bench's own analysis of each film (every method) is left
    # out here: the rows compared are the sweep's, which the bench records beside its own.
    text = analyser_settings.QUICK_SPEC.read_text()
    spec = tmp_path / "one.toml"
    spec.write_text(text[: text.index("[[points]]", text.index("[[points]]") + 1)])
    monkeypatch.setattr(analyser, "_case_record", lambda point, options, row, log, started: {"case": point.labels["case"], "group": "mixed"})
    monkeypatch.setattr(analyser, "summarise", lambda cases: {})
    monkeypatch.setattr(analyser, "targets_met", lambda summaries: {})
    benched = analyser.run(read_sweep(spec), Context(tmp_path / "bench", log=lambda message: None))["sweep"]
    assert main(["sweep", str(spec), "--out", str(tmp_path / "sweep"), "--json"]) == 0
    swept = json.loads(capsys.readouterr().out)

    def comparable(rows: list[dict]) -> list[dict]:
        return [row | {"video": Path(row["video"]).parent.name, "seconds": None} for row in rows]

    assert len(swept) == 1 and swept[0]["status"] in ("ok", "warning")
    assert swept[0]["case"].startswith("quick-a") and swept[0]["group"] == "named"
    assert comparable(benched) == comparable(swept)
    summary = (tmp_path / "bench" / "summary.csv").read_text().splitlines()[0]
    assert summary == (tmp_path / "sweep" / "summary.csv").read_text().splitlines()[0]


def test_the_bench_analyses_each_film_with_every_method_told_what_the_sweep_was_told(tmp_path: Path) -> None:
    """A rolling shutter told to the analysis as the film's own bench ([analysis] simulated_bench):
    the bench's sinefit is the sweep's answer, dated by rows. Analysed with the spec's options
    alone, the bench's methods were off by the rows' share of the readout (about 1 ms here)."""
    spec = tmp_path / "rolling.toml"
    spec.write_text(
        "[[points]]\nduration_s = 3.0\nlayout = \"led-above\"\nlabels = { case = \"rolling\", group = \"hard\" }\n"
        "camera = { fps = 120.0, readout_s = 0.006, width = 320, height = 240, subsamples = 4 }\n"
        "[analysis]\nmethod = \"sinefit\"\nsimulated_bench = true\n"
    )
    point = read_sweep(spec).points(tmp_path / "out")[0]
    row = analyser.measure_point(point, log=lambda message: None)
    sinefit = row["bench"]["methods"]["sinefit"]
    assert sinefit["latency_ms"] == pytest.approx(row["latency_ms"], abs=1e-9)
    assert abs(sinefit["error_ms"]) < 0.3 and sinefit["covered"]
    assert all(abs(method["error_ms"]) < 0.3 for method in row["bench"]["methods"].values())


def test_grid_runs_the_points_of_its_group(monkeypatch, tmp_path: Path) -> None:
    ran: list[str] = []

    def measured(point: SweepPoint, log) -> dict:
        ran.append(point.labels["case"])
        return {"index": point.index, "bench": {"case": point.labels["case"], "group": point.labels["group"]}}

    monkeypatch.setattr(analyser, "measure_point", measured)
    monkeypatch.setattr(analyser, "summarise", lambda cases: {"cases": len(cases)})
    monkeypatch.setattr(analyser, "targets_met", lambda summaries: {})
    report = analyser.run(analyser.of_groups(read_sweep(analyser_settings.QUICK_SPEC), "hard"), Context(tmp_path, log=lambda message: None))
    assert ran == [case["case"] for case in report["cases"]] and len(ran) == 1 and ran[0].startswith("quick-dim-led")
    assert report["summaries"] == {"all": {"cases": 1}, "hard": {"cases": 1}}
