"""Sweeps: a TOML grid over the simulation's options, every point simulated and analysed."""

from __future__ import annotations

from pathlib import Path

import pytest

from rig.errors import ConfigError
from rig.service.sweep import build, read_sweep, run_sweep
from rig.sim.config import SimulationConfig

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
    with pytest.raises(ConfigError, match="has no 'fpss'"):
        build(SimulationConfig, {"camera.fpss": 60.0})
    with pytest.raises(ConfigError, match="single value"):
        build(SimulationConfig, {"seed.x": 1})


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
        ("[grid]\nseed = [1]\n[analysis]\nfps = 3\n", "\\[analysis\\] takes"),
        ("[grid\n", "not valid TOML"),
        ("points = [1]\n", "list of tables"),
        ("[[points]]\nlabels = 3\n", "labels must be a table"),
    ],
)
def test_a_bad_sweep_file_says_what_is_wrong(tmp_path: Path, text: str, message: str) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    with pytest.raises(ConfigError, match=message):
        read_sweep(spec)
