"""Sweeps: a TOML grid over the simulation's options, every point simulated and analysed."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from analysis.hints.hint import CONTRADICTS
from rig.errors import ConfigError
from rig.service import sweep as sweep_service
from rig.service.sweep import SIMULATED_BENCH, SIMULATED_ROIS, Sweep, build, read_sweep, run_sweep, settings_of, simulated_bench, write_sweep
from rig.sim.board import SimulatedBoardConfig
from rig.sim.camera import CameraConfig
from rig.sim.config import SimulationConfig
from rig.sim.impairments_config import FilmImpairments
from rig.sim.pendulum import PendulumConfig

SPEC = """
[base]
duration_s = 3.0
camera.fps = 120.0
camera.width = 320
camera.height = 240
camera.subsamples = 4
display = { width = 160, height = 120 }

[grid]
"pendulum.period_s" = [0.7, 1.1]

[analysis]
method = "sinefit"
"""


def test_every_point_is_simulated_analysed_and_compared_with_its_truth(tmp_path: Path) -> None:
    spec = tmp_path / "sweep.toml"
    spec.write_text(SPEC)
    rows, summary = run_sweep(read_sweep(spec), tmp_path / "out")
    assert [row["pendulum.period_s"] for row in rows] == ["0.7", "1.1"]
    for row in rows:
        assert row["status"] in ("ok", "warning")
        assert abs(row["error_ms"]) < 1.0
        assert row["error_ms"] == pytest.approx(row["latency_ms"] - row["truth_ms"])
    assert summary.exists() and summary.with_suffix(".json").exists()
    assert (tmp_path / "out" / "point001" / "truth.json").exists()


def test_settings_are_checked_against_the_configs_fields() -> None:
    config = build(SimulationConfig, {"camera.fps": 60.0, "predictor_params.min_interval": 1e-6, "board.blink_bits": 8})
    assert config.camera.fps == 60.0 and config.predictor_params == {"min_interval": 1e-6} and config.board.blink_bits == 8
    with pytest.raises(ConfigError, match="^the sweep: unknown key camera.fpss; CameraConfig takes fps, exposure_s, "):
        build(SimulationConfig, {"camera.fpss": 60.0})
    with pytest.raises(ConfigError, match="^the sweep: seed must be a whole number, not {'x': 1}$"):
        build(SimulationConfig, {"seed.x": 1})
    assert build(SimulationConfig, {"app_frame_ms": "measured", "warp_ms": 2.0}) == SimulationConfig(app_frame_ms=None, warp_ms=2.0)
    with pytest.raises(ConfigError, match="^the sweep: app_frame_ms must be a number or \"measured\", not 'measure'$"):
        build(SimulationConfig, {"app_frame_ms": "measure"})
    with pytest.raises(ConfigError, match="^the sweep: camera.fps must be a positive number of frames per second from 1 to 10000, got 0.5$"):
        build(SimulationConfig, {"camera.fps": 0.5})


def test_points_given_one_by_one_follow_the_grids_with_their_labels_or_their_settings(tmp_path: Path) -> None:
    spec = tmp_path / "sweep.toml"
    spec.write_text("""
[base]
duration_s = 3.0

[grid]
seed = [1, 2]

[[points]]
labels = { case = "dim LED", group = "hard" }
camera = { fps = 120.0, impairments = { dim_led = 0.35 } }

[[points]]
"pendulum.period_s" = 0.7
""")
    sweep = read_sweep(spec)
    points = sweep.points(tmp_path / "out")
    assert [point.labels for point in points] == [
        {"seed": "1"}, {"seed": "2"}, {"case": "dim LED", "group": "hard"}, {"pendulum.period_s": "0.7"}
    ]  # fmt: skip
    assert sweep.labels == ["seed", "case", "group", "pendulum.period_s"]
    assert points[2].config.camera.impairments.dim_led == 0.35 and points[2].config.duration_s == 3.0
    assert points[3].config.pendulum.period_s == 0.7 and points[3].out_dir == tmp_path / "out" / "point003"
    hard = sweep.only(lambda labels: labels.get("group") == "hard").points(tmp_path / "out")
    assert [(point.config, point.labels) for point in hard] == [(points[2].config, points[2].labels)]


@pytest.mark.parametrize(
    "text, message",
    [
        ("[grid]\n", "no \\[grid\\]"),
        ("[grid]\nseed = 3\n", "non-empty list"),
        ("[gird]\nseed = [1]\n", "unknown table"),
        ("[grid]\nseed = [1]\n[analysis]\nspeed = 3\n", "\\[analysis\\]: unknown key speed; AnalysisOptions takes fps, "),
        ("[grid]\nseed = [1]\n[analysis]\nmethod = \"guess\"\n", "\\[analysis\\]: method must be one of fft, "),
        ("[grid\n", "not valid TOML"),
        ("points = [1]\n", "list of tables"),
        ("[[points]]\nlabels = 3\n", "labels must be a table"),
        ("[grid]\nseed = [1]\n[analysis]\nsimulated_rois = 1\n", "simulated_rois is true or false"),
        ("[grid]\nseed = [1]\n[analysis]\nsimulated_bench = \"yes\"\n", "simulated_bench is true or false"),
        ("[grid]\nseed = [1]\n[analysis]\nsimulated_bench = true\nbench = \"b.toml\"\n", "both a bench profile and simulated_bench"),
    ],
)
def test_a_bad_sweep_file_says_what_is_wrong(tmp_path: Path, text: str, message: str) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    with pytest.raises(ConfigError, match=message):
        read_sweep(spec)


def test_a_config_written_as_a_points_settings_builds_back_the_same_config(tmp_path: Path) -> None:
    config = SimulationConfig(
        duration_s=4.5, pendulum=PendulumConfig(period_s=1.7), camera=CameraConfig(fps=90.0, impairments=FilmImpairments(dim_led=0.35)),
        renderer="warp:recon=grid", predictor_params={"min_interval": 1e-6}, app_frame_ms=None, warp_ms=None,
        board=SimulatedBoardConfig(blink_bits=8),
    )  # fmt: skip
    settings = settings_of(config)
    assert settings["app_frame_ms"] == settings["warp_ms"] == "measured" and "seed" not in settings
    assert settings["camera"] == {"fps": 90.0, "impairments": {"dim_led": 0.35}}
    assert Sweep({}, {}, explicit=[settings]).points(tmp_path)[0].config == config
    assert settings_of(SimulationConfig()) == {}


def test_a_written_sweep_reads_back_as_the_same_sweep(tmp_path: Path) -> None:
    sweep = Sweep(
        {"duration_s": 3.0, "camera": {"fps": 120.0}},
        {"pendulum.period_s": [0.7, 1.1], "predictor": ["hold", "slerp"]},
        {"method": "sinefit", "latency_range_ms": [0.0, 200.0], SIMULATED_ROIS: True},
        [{"labels": {"case": 'a "quoted" case', "n": 3}, "renderer": "warp", "app_frame_ms": "measured",
          "camera": {"impairments": {"occluded": "led"}}}],
    )  # fmt: skip
    path = tmp_path / "sweep.toml"
    write_sweep(sweep, path, "a sweep\nof two lines")
    assert path.read_text().startswith("# a sweep\n# of two lines\n")
    again = read_sweep(path)
    assert again == sweep
    assert [p.config for p in again.points(tmp_path)] == [p.config for p in sweep.points(tmp_path)]


def test_a_sweep_with_simulated_rois_analyses_each_video_within_its_simulations_regions(tmp_path: Path, monkeypatch) -> None:
    requests = []

    def analysed(item):
        requests.append(item.request)
        return analysed_row(item)

    analysed_row = sweep_service.analysed_row
    monkeypatch.setattr(sweep_service, "analysed_row", analysed)
    spec = tmp_path / "sweep.toml"
    spec.write_text(SPEC.replace('method = "sinefit"', 'method = "sinefit"\nsimulated_rois = true').replace("[0.7, 1.1]", "[0.7]"))
    rows, _ = run_sweep(read_sweep(spec), tmp_path / "out")
    truth = json.loads((tmp_path / "out" / "point000" / "truth.json").read_text())
    assert [(r.options.led_roi, r.options.sphere_roi) for r in requests] == [(tuple(truth["led_roi"]), tuple(truth["sphere_roi"]))]
    assert abs(rows[0]["error_ms"]) < 1.0


def test_a_simulated_bench_is_each_points_own_camera_display_and_led_side() -> None:
    config = SimulationConfig(
        camera=CameraConfig(fps=120.0, exposure_s=0.004, readout_s=0.006, impairments=FilmImpairments(mirrored=True)),
        layout="led-above",
    )
    profile = simulated_bench(config)
    assert (profile.camera.fps, profile.camera.exposure_ms, profile.camera.readout_ms) == (120.0, 4.0, 6.0)
    assert profile.display.refresh_hz == config.display.refresh_hz and profile.layout.led_side == "right"
    assert simulated_bench(SimulationConfig(layout="0.75,0.5,0.3/0.3,0.5,0.4")).layout.led_side == "right"


def test_a_sweep_with_a_simulated_bench_analyses_each_video_told_its_own_bench(tmp_path: Path) -> None:
    spec = tmp_path / "sweep.toml"
    spec.write_text(
        "[[points]]\nduration_s = 3.0\nlayout = \"led-above\"\n"
        "camera = { fps = 120.0, readout_s = 0.006, width = 320, height = 240, subsamples = 4 }\n"
        f"[analysis]\nmethod = \"sinefit\"\n{SIMULATED_BENCH} = true\n"
    )
    point = read_sweep(spec).points(tmp_path / "out")[0]
    run = sweep_service.simulate_and_analyse(point)
    told = {check.hint.name: check for check in run.result.hints}
    assert told["readout_ms"].hint.value == 6.0 and told["readout_ms"].hint.source.endswith("truth.json [camera] readout_ms: the simulation")
    assert CONTRADICTS not in (told["led_side"].verdict, told["display_hz"].verdict, told["exposure_ms"].verdict)
    low, high = run.result.ci95_ms
    assert run.result.to_dict()["rolling_shutter"]["readout_source"] != "bounded"
    assert low <= run.simulation.truth.latency_ms <= high and abs(run.row["error_ms"]) < 0.3
