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


@pytest.mark.parametrize(
    "text, message",
    [
        ("[grid]\n", "no \\[grid\\]"),
        ("[grid]\nseed = 3\n", "non-empty list"),
        ("[gird]\nseed = [1]\n", "unknown table"),
        ("[grid]\nseed = [1]\n[analysis]\nfps = 3\n", "\\[analysis\\] takes"),
        ("[grid\n", "not valid TOML"),
    ],
)
def test_a_bad_sweep_file_says_what_is_wrong(tmp_path: Path, text: str, message: str) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    with pytest.raises(ConfigError, match=message):
        read_sweep(spec)
