"""Small simulated videos for the batch, sweep and report tests: short, low-resolution, quick to analyse."""

from __future__ import annotations

from pathlib import Path

import pytest

from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig

SMALL_CAMERA = CameraConfig(fps=120.0, width=320, height=240, subsamples=4)


def small_config(**overrides) -> SimulationConfig:
    settings = dict(duration_s=3.0, camera=SMALL_CAMERA, display=DisplayConfig(width=160, height=120))
    settings.update(overrides)
    return SimulationConfig(**settings)


@pytest.fixture(scope="session")
def small_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two small simulated runs (different pendulum periods) and a file that is no video."""
    root = tmp_path_factory.mktemp("runs")
    runs = {
        "fast": simulate(small_config(pendulum=PendulumConfig(period_s=0.7), seed=1), root / "fast").video_path,
        "slow": simulate(small_config(pendulum=PendulumConfig(period_s=1.2), seed=2), root / "slow").video_path,
    }
    broken = root / "broken" / "video.avi"
    broken.parent.mkdir()
    broken.write_text("not a video")
    return runs | {"broken": broken}
