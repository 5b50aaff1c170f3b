"""The whole chain on synthetic pendulum video: the analyser must find the latency the simulation knows."""

import json
from pathlib import Path

import pytest

import analysis
from rig.cli import EXIT_WARNINGS, main
from rig.service import SimulationConfig, simulate
from rig.sim.board import SimulatedBoardConfig
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig
from rig.sim.tracker import TrackerConfig

TOLERANCE_MS = 1.0

CONFIGURATIONS = {
    "60Hz-hold": SimulationConfig(duration_s=6.0, predictor="hold"),
    "120Hz-slerp": SimulationConfig(duration_s=6.0, predictor="slerp", display=DisplayConfig(refresh_hz=120.0), seed=2),
    "heavy-scene-long-frame": SimulationConfig(duration_s=6.0, scene_triangles=20_000, app_frame_ms=45.0, seed=3, predictor="hold"),
    "144Hz-fast-swing": SimulationConfig(duration_s=6.0, display=DisplayConfig(refresh_hz=144.0), seed=4),
}


@pytest.mark.parametrize("name", CONFIGURATIONS)
def test_analyser_recovers_the_true_latency(name: str, tmp_path: Path) -> None:
    run = simulate(CONFIGURATIONS[name], tmp_path)
    result = analysis.analyse(run.video_path)
    assert not result.ambiguous
    assert result.frames_used == result.frames
    assert result.latency_ms == pytest.approx(run.truth.latency_ms, abs=TOLERANCE_MS)


def test_prediction_and_scene_cost_move_the_latency_the_right_way(tmp_path: Path) -> None:
    """Slerp prediction hides latency, an expensive scene adds it: the truth must say so."""
    latency = {
        name: simulate(CONFIGURATIONS[name], tmp_path / name).truth.latency_ms
        for name in ("60Hz-hold", "heavy-scene-long-frame")
    }
    slerp = simulate(SimulationConfig(duration_s=6.0, predictor="slerp"), tmp_path / "slerp").truth.latency_ms
    assert slerp < latency["60Hz-hold"] - 15.0
    assert latency["heavy-scene-long-frame"] > latency["60Hz-hold"] + 30.0


def test_demo_command_agrees_with_truth(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--out", str(tmp_path), "--duration", "4", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["agrees"]
    assert abs(report["difference_ms"]) <= TOLERANCE_MS
    assert (tmp_path / "demo.png").stat().st_size > 10_000
    assert report["analysis"]["warnings"] == []
    low, high = report["analysis"]["ci95_ms"]
    assert low <= report["latency_true_ms"] <= high


@pytest.mark.slow
def test_the_demo_at_its_defaults_carries_no_warning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """What `make demo` runs: the analysis is told the simulated bench, which follows the filming
    advice, so a newcomer's first run ends without a caveat."""
    assert main(["demo", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "warning" not in out and "OK" in out


def test_a_board_recording_fixes_a_latency_beyond_half_a_period(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The lab procedure: the board blinks its code while the pendulum is held, then it is released.
    440 ms on a 0.6 s pendulum: -160 ms fits the phase as well, and a narrow swing has too little
    chirp to tell them apart; the encoder's start of swing, on the video's clock, does."""
    config = SimulationConfig(
        duration_s=7.0,
        pendulum=PendulumConfig(period_s=0.6, amplitude_deg=8.0, quality=500.0, release_s=2.5),
        tracker=TrackerConfig(transport_delay_s=0.4),
        camera=CameraConfig(fps=120.0),
        board=SimulatedBoardConfig(board_offset_s=37.5, blink_start_s=0.2, blink_bits=32),
        warmup_s=0.9,
        predictor="hold",  # the latency must stay beyond half a period: no prediction hides part of it
    )
    run = simulate(config, tmp_path)
    argv = ["analyse", str(run.video_path), "--board", str(tmp_path / "board"), "--latency-range=-200,1000", "--json"]
    # The blink code switches the LED off in some frames: a result with a warning, exit status 3.
    assert main(argv) == EXIT_WARNINGS
    report = json.loads(capsys.readouterr().out)
    assert any(warning.startswith("the LED was missing") for warning in report["warnings"])
    assert report["ci95_ms"][0] <= run.truth.latency_ms <= report["ci95_ms"][1]
    assert not report["ambiguous"] and "board encoder start" in report["cycles"]["how"]
    assert report["latency_ms"] == pytest.approx(run.truth.latency_ms, abs=TOLERANCE_MS)
    low, high = report["board"]["offset_interval_s"]
    assert low <= 37.5 <= high
    assert report["cycles"]["events_ms"]["board encoder start"] == pytest.approx(run.truth.latency_ms, abs=20.0)
    assert main(argv[:-1]) == EXIT_WARNINGS
    lines = capsys.readouterr().out.splitlines()
    board = next(line for line in lines if line.startswith("board: "))
    assert f"offset {report['board']['offset_s']:.4f} s" in board
    lag_ms = report["cycles"]["events_ms"]["board encoder start"]
    assert board.endswith(f"the sphere left rest {lag_ms:.0f} ms after the encoder did")
