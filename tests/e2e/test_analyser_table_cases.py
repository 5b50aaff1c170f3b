"""The four videos of the analyser's hard cases, and the commonest lab setting (240 fps exposing half
of each frame), made by the simulator: each must give a number whose
95 % interval holds the truth, with a warning that names the cause where the camera's sampling of
the display could bias it, or a clear refusal; never a tight interval around a wrong number.

The clips are short and small (4 s, 320 x 240) so that CI stays quick; the renderer holds the last
pose (no prediction), as in the runs the cases were found with (42 ms of latency).
"""

from pathlib import Path

import numpy as np
import pytest

import analysis
from analysis.video.sources import open_frames
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig

SMALL = {"width": 320, "height": 240}
DURATION_S = 4.0


def _run(tmp_path: Path, fps: float, display_hz: float, exposure: float = 1.0, phase: float = 0.0) -> tuple[np.ndarray, float]:
    """The frames and true latency (ms) of a short run; ``exposure`` a fraction of the frame
    interval, ``phase`` the display's refreshes against the camera's frames (of a refresh)."""
    config = SimulationConfig(
        duration_s=DURATION_S,
        camera=CameraConfig(fps=fps, exposure_s=exposure / fps, **SMALL),
        display=DisplayConfig(refresh_hz=display_hz, phase=phase),
        predictor="hold",
    )
    run = simulate(config, tmp_path)
    frames = np.stack([image for _, image in open_frames(run.video_path).frames()])
    return frames, run.truth.latency_ms


def _holds_truth(result: analysis.LatencyResult, truth_ms: float) -> None:
    low, high = result.ci95_ms
    assert low <= truth_ms <= high, (truth_ms, result.ci95_ms, result.warnings)
    assert not result.ambiguous


def test_a_60_fps_camera_on_a_60_hz_display(tmp_path: Path) -> None:
    # Phase-locked, exposing whole frames: each frame averages one whole refresh, so nothing is
    # biased; the video cannot show the refresh, and the interval allows for an exposure a little
    # short of the whole frame.
    frames, truth = _run(tmp_path, 60.0, 60.0)
    result = analysis.analyse(frames, analysis.AnalysisOptions(fps=60.0))
    _holds_truth(result, truth)
    assert result.latency_ms == pytest.approx(truth, abs=0.3)


def test_a_144_fps_camera_on_a_144_hz_display(tmp_path: Path) -> None:
    frames, truth = _run(tmp_path, 144.0, 144.0)
    result = analysis.analyse(frames, analysis.AnalysisOptions(fps=144.0))
    _holds_truth(result, truth)
    assert result.latency_ms == pytest.approx(truth, abs=0.3)


@pytest.mark.slow
def test_a_240_fps_run_with_every_fourth_frame_kept_at_each_of_four_phases(tmp_path: Path) -> None:
    # 60 fps with a quarter-refresh exposure: phase-locked, each phase of the refresh reads the
    # latency off by up to 6 ms. No phase is told by the video: every interval must hold the truth
    # and say why it is wide.
    frames, truth = _run(tmp_path, 240.0, 60.0)
    for phase in range(4):
        result = analysis.analyse(frames[phase::4], analysis.AnalysisOptions(fps=60.0))
        _holds_truth(result, truth)
        assert any("does not show whether the display refreshes" in w or "phase-locked" in w for w in result.warnings), phase
        assert result.ci95_ms[1] - result.ci95_ms[0] > 8.0


def test_the_led_half_of_the_image_dimmed_to_35_percent(tmp_path: Path) -> None:
    # The sphere is now the brighter blob; the display's refresh steps say which is which.
    frames, truth = _run(tmp_path, 240.0, 60.0)
    half = frames.shape[2] // 2
    dimmed = frames.copy()
    dimmed[:, :, :half] = np.rint(dimmed[:, :, :half] * 0.35).astype(np.uint8)
    result = analysis.analyse(dimmed, analysis.AnalysisOptions(fps=240.0))
    _holds_truth(result, truth)
    assert result.latency_ms > 0
    assert "refresh steps +" in result.led_rule
    assert result.led_roi.x + result.led_roi.width / 2 < half < result.sphere_roi.x + result.sphere_roi.width / 2


# The commonest lab setting, which read about 1 ms short with an interval of +-0.02 ms: 240 fps
# exposing half of each frame visits four phases of each 60 Hz refresh (two of a 120 Hz one) and
# does not tile it. The interval must hold the truth, with a warning that names the cause.
HALF_FRAME = 0.5
OFF_STEP_PHASE = 0.37


@pytest.mark.parametrize("display_hz", [60.0, 120.0])
def test_a_240_fps_camera_exposing_half_of_each_frame_the_settings_unknown(tmp_path: Path, display_hz: float) -> None:
    frames, truth = _run(tmp_path, 240.0, display_hz, exposure=HALF_FRAME, phase=OFF_STEP_PHASE)
    result = analysis.analyse(frames, analysis.AnalysisOptions(fps=240.0))
    _holds_truth(result, truth)
    assert any("the 240 fps camera" in warning for warning in result.warnings)


def _told(fps: float, display_hz: float, exposure: float) -> analysis.AnalysisOptions:
    """The options of a lab that knows its bench: the display's rate, the exposure and the global shutter."""
    return analysis.AnalysisOptions(fps=fps, display_hz=display_hz, exposure_ms=exposure / fps * 1e3, readout_ms=0.0)


# Told the display and the exposure, the analysis once placed the refreshes as if the sphere's rows all
# switched at one instant and corrected +0.94 ms where the 60 Hz film's bias is +0.46 ms, its interval
# missing the truth by 0.3 ms. The sphere's rows switch one after another as the scan-out reaches them.
@pytest.mark.parametrize("display_hz", [60.0, 120.0])
def test_a_240_fps_camera_exposing_half_of_each_frame_the_settings_given(tmp_path: Path, display_hz: float) -> None:
    frames, truth = _run(tmp_path, 240.0, display_hz, exposure=HALF_FRAME, phase=OFF_STEP_PHASE)
    result = analysis.analyse(frames, _told(240.0, display_hz, HALF_FRAME))
    _holds_truth(result, truth)
    assert any("the 240 fps camera" in warning for warning in result.warnings)
    if display_hz == 60.0:
        # Narrower than the +-1.04 ms any phase allows: four phases of each refresh place the refreshes
        # (two phases of a 120 Hz one do not, the sphere's rows unknown, and the interval holds them all).
        assert (result.ci95_ms[1] - result.ci95_ms[0]) / 2 < 0.7


# Equal rates exposing part of a frame: every frame sees the display at one phase, and the sphere's
# double images are all the video says of it. Where a switch falls near the exposure's edge some of
# the sphere's rows show two images and others one; read as one image pair, they once placed the
# switch inside the exposure, and the interval missed the truth by 0.3-0.4 ms.
@pytest.mark.parametrize(("fps", "exposure", "phase"), [(144.0, 0.3, 0.55), (120.0, 0.5, 0.5497901303853616)])
def test_equal_camera_and_display_rates_at_a_short_exposure(tmp_path: Path, fps: float, exposure: float, phase: float) -> None:
    frames, truth = _run(tmp_path, fps, fps, exposure=exposure, phase=phase)
    result = analysis.analyse(frames, _told(fps, fps, exposure))
    _holds_truth(result, truth)
    assert abs(result.latency_ms - truth) > 0.8  # the film is biased, and the interval says by how much it may be
    assert any("phase-locked" in warning for warning in result.warnings)
