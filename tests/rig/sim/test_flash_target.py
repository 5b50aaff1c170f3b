"""The simulator's calibration targets (`rig.sim.flash`): a flashing light filling the view, or the
display flashing full-field; and the shutter estimator on their films, whose readout and exposure
the simulation knows, from 30 to 240 fps."""

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.shutter import ShutterOptions, measure_shutter, suggest_flash_hz
from rig.cli import main
from rig.errors import ConfigError
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.flash import FlashTarget, on_shares

# A display panel tall in a small frame: its height in rows sets how well its scan-out is removed.
TALL_PANEL = "0.06,0.5,0.05/0.58,0.5,0.76"


@given(st.floats(-1.0, 1.0), st.floats(1e-4, 0.05), st.floats(20.0, 1000.0), st.floats(0.05, 0.95), st.floats(0.0, 0.01))
def test_a_row_gets_the_share_of_its_window_the_light_was_on(start, exposure, hz, duty, phase):
    target = FlashTarget(hz=hz, duty=duty, phase_s=phase)
    instants = start + (np.arange(100_000) + 0.5) / 100_000 * exposure
    sampled = np.mean(np.mod((instants - phase) * hz, 1.0) < duty)
    assert on_shares(np.array([start]), exposure, target)[0] == pytest.approx(sampled, abs=2e-4)


@pytest.mark.parametrize(
    "fields, words",
    [({"source": "lamp"}, "flash.source must be one of light, display"), ({"hz": 0.0}, "flash.hz must be a positive number of Hz"),
     ({"duty": 1.0}, "flash.duty must be a positive number below 1"), ({"refreshes": 1}, "from 2 to 1000")],
)
def test_a_target_out_of_range_is_refused(fields, words):
    with pytest.raises(ConfigError, match=words):
        FlashTarget(**fields)


def film(tmp_path: Path, fps: float, readout: float, exposure: float, target: FlashTarget, layout: str = "side-by-side") -> Path:
    camera = CameraConfig(fps=fps, exposure_s=exposure, readout_s=readout, width=160, height=120)
    flash_hz = target.hz if target.source == "light" else 60.0 / target.refreshes
    config = SimulationConfig(duration_s=max(1.0, 60 / fps, 12 / flash_hz), camera=camera, flash=target, layout=layout, seed=int(fps))
    return simulate(config, tmp_path).video_path


def assert_measured(result, readout, exposure):
    assert result.readout_s == pytest.approx(readout, rel=0.05)
    assert result.exposure_s == pytest.approx(exposure, rel=0.10)
    assert result.readout_ci95_s[0] <= readout <= result.readout_ci95_s[1]
    assert result.exposure_ci95_s[0] <= exposure <= result.exposure_ci95_s[1]


@pytest.mark.parametrize("fps, readout_share, exposure_share", [(30, 0.9, 1.0), (60, 0.5, 0.3), (120, 0.8, 0.1), (240, 0.9, 1.0)])
def test_a_light_filmed_by_the_simulated_camera_gives_its_readout_and_exposure(tmp_path, fps, readout_share, exposure_share):
    readout, exposure = readout_share / fps, exposure_share / fps
    flash = round(suggest_flash_hz(fps, exposure), 2)
    result = measure_shutter(film(tmp_path, fps, readout, exposure, FlashTarget("light", hz=flash)), flash)
    assert_measured(result, readout, exposure)
    assert result.rows == (0, 119) and result.warnings == ()


@pytest.mark.parametrize("fps, readout_share, exposure_share", [(120, 0.8, 0.5), (240, 0.9, 1.0)])
def test_a_display_flashing_full_field_gives_the_readout_once_its_scan_out_is_removed(tmp_path, fps, readout_share, exposure_share):
    readout, exposure = readout_share / fps, exposure_share / fps
    video = film(tmp_path, fps, readout, exposure, FlashTarget("display", refreshes=2), layout=TALL_PANEL)
    result = measure_shutter(video, 30.0, ShutterOptions(source="display", display_hz=60.0, scanout_share=1.0))
    assert_measured(result, readout, exposure)
    assert result.source == "display"


def test_a_global_shutter_filming_the_light_reads_zero(tmp_path):
    video = film(tmp_path, 120, 0.0, 2e-3, FlashTarget("light", hz=83.3))
    result = measure_shutter(video, 83.3)
    assert result.global_shutter and result.readout_ci95_s[1] < 0.1e-3
    assert result.exposure_s == pytest.approx(2e-3, rel=0.02)


def test_rig_simulate_films_a_flashing_light_and_records_it(tmp_path, capsys):
    arguments = ["simulate", "--out", str(tmp_path), "--duration", "1", "--camera-fps", "60", "--readout-ms", "12"]
    assert main([*arguments, "--flash-hz", "21.7", "--flash-duty", "0.25"]) == 0
    assert "a light flashing at 21.7 Hz (25% on), filmed with a 12 ms readout and a 16.6667 ms exposure" in capsys.readouterr().out
    record = json.loads((tmp_path / "truth.json").read_text())["config"]
    assert record["flash"]["source"] == "light" and record["flash"]["duty"] == 0.25


def test_a_run_without_a_target_records_none(tmp_path):
    assert "flash" not in SimulationConfig().to_dict()


def test_a_light_and_a_flashing_display_are_one_or_the_other(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", "--out", str(tmp_path), "--flash-hz", "20", "--flash-display", "2"])
    assert exit_.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err
