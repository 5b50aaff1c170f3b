"""The whole chain on synthetic pendulum video: the analyser must find the latency the simulation knows."""

import json
from pathlib import Path

import pytest

import analysis
from rig.cli import main
from rig.session import SimulationConfig, simulate
from rig.sim.display import DisplayConfig

TOLERANCE_MS = 1.0

CONFIGURATIONS = {
    "60Hz-hold": SimulationConfig(duration_s=6.0, predictor="hold"),
    "120Hz-slerp": SimulationConfig(duration_s=6.0, predictor="slerp", display=DisplayConfig(refresh_hz=120.0), seed=2),
    "heavy-scene-long-frame": SimulationConfig(duration_s=6.0, scene_triangles=20_000, app_frame_ms=45.0, seed=3),
    "144Hz-fast-swing": SimulationConfig(duration_s=6.0, display=DisplayConfig(refresh_hz=144.0), seed=4),
}


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_analyser_recovers_the_true_latency(name: str, tmp_path: Path) -> None:
    run = simulate(CONFIGURATIONS[name], tmp_path)
    result = analysis.analyse(run.video_path)
    assert not result.ambiguous
    assert result.frames_used == result.frames
    assert result.latency_ms == pytest.approx(run.truth["latency_ms"], abs=TOLERANCE_MS)


def test_prediction_and_scene_cost_move_the_latency_the_right_way(tmp_path: Path) -> None:
    """Slerp prediction hides latency, an expensive scene adds it: the truth must say so."""
    latency = {
        name: simulate(CONFIGURATIONS[name], tmp_path / name).truth["latency_ms"]
        for name in ("60Hz-hold", "heavy-scene-long-frame")
    }
    slerp = simulate(SimulationConfig(duration_s=6.0, predictor="slerp"), tmp_path / "slerp").truth["latency_ms"]
    assert slerp < latency["60Hz-hold"] - 15.0
    assert latency["heavy-scene-long-frame"] > latency["60Hz-hold"] + 30.0


def test_demo_command_agrees_with_truth(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path), "--duration", "4", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["agrees"]
    assert abs(report["difference_ms"]) <= TOLERANCE_MS
    assert (tmp_path / "demo.png").stat().st_size > 10_000
