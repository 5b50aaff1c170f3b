"""Which refresh rates and phases a sphere's timing residuals allow, on residuals made from a known
display: the bias is found where the frames show the refreshes, and left wide where they cannot."""

import math

import numpy as np
import pytest

from analysis.sampling.inference import refresh_hypotheses
from analysis.sampling.model import exposure_bias, frame_phases
from analysis.sampling.residuals import TimingResiduals
from analysis.sampling.rows import SphereRows

SWING_HZ = 1.0
SPEED_PX_S = 600.0
NOISE_PX = 0.05


def residuals(fps: float, refresh_hz: float, exposure_s: float, phase: float, seconds: float = 6.0) -> tuple[TimingResiduals, float]:
    """The residuals a display of ``refresh_hz`` at ``phase`` leaves, and the true weighted mean bias (s)."""
    t = np.arange(round(seconds * fps)) / fps
    v = SPEED_PX_S * np.cos(2 * math.pi * SWING_HZ * t)
    s = frame_phases(t, refresh_hz, phase)
    bias = exposure_bias(s, exposure_s * refresh_hz) / refresh_hz
    mean = float(v**2 @ bias / (v**2).sum())
    rng = np.random.default_rng(3)
    r = -v * (bias - mean) + NOISE_PX * rng.standard_normal(t.size)
    return TimingResiduals(t, r, v, np.arange(t.size), 1.0 / fps), mean


def test_four_phases_of_a_60_hz_display_are_placed_and_the_bias_found() -> None:
    # 240 fps exposing half of each frame: the biases of the four phases do not average out. One
    # exposure in four holds the switch: the four phases' timing places the refreshes.
    data, truth = residuals(240.0, 60.0, 1 / 480, 0.2)
    assert abs(truth) > 0.15e-3
    hypotheses = refresh_hypotheses(data, 240.0, None, (1 / 480, 1 / 480), 24)
    best = hypotheses[0]
    assert best.refresh_hz == pytest.approx(60.0, abs=0.01)
    assert best.mean_s == pytest.approx(truth, abs=0.05e-3)
    low, high = best.quantiles_s(0.025, 0.975)
    assert low - 0.02e-3 <= truth <= high + 0.02e-3
    assert high - low < 0.2e-3


def test_a_switch_between_exposures_leaves_the_gap_open() -> None:
    # The same camera with the switch in the gap between two exposures: no frame shows it, and it
    # could be anywhere in the gap, T / 4 - E wide, so the bias anywhere in +-(T / 4 - E) / 2.
    data, truth = residuals(240.0, 60.0, 1 / 480, 0.1)
    low, high = refresh_hypotheses(data, 240.0, 60.0, (1 / 480, 1 / 480), 24)[0].range_s(0.005, 0.995)
    bound = (1 / 240 - 1 / 480) / 2
    assert low == pytest.approx(-bound, abs=0.1e-3) and high == pytest.approx(bound, abs=0.1e-3)
    assert low <= truth <= high


def test_a_phase_locked_camera_leaves_the_whole_bias_range_open() -> None:
    # 60 fps on 60 Hz exposing a quarter refresh: every frame alike, nothing places the switch.
    data, truth = residuals(60.0, 60.0, 1 / 240, 0.3)
    hypotheses = refresh_hypotheses(data, 60.0, 60.0, (1 / 240, 1 / 240), 6)
    assert len(hypotheses) == 1
    low, high = hypotheses[0].range_s(0.005, 0.995)
    bound = (1 / 60 - 1 / 240) / 2
    assert low == pytest.approx(-bound, abs=0.2e-3) and high == pytest.approx(bound, abs=0.2e-3)
    assert low <= truth <= high


def test_a_drifting_display_clock_is_tuned_to() -> None:
    # The display runs 0.05 % fast against a nominal 60 Hz: over 6 s its phase walks 0.18 of a refresh.
    data, truth = residuals(240.0, 60.03, 1 / 480, 0.6)
    best = refresh_hypotheses(data, 240.0, 60.0, (1 / 480, 1 / 480), 24)[0]
    assert best.refresh_hz == pytest.approx(60.03, abs=0.005)
    assert best.mean_s == pytest.approx(truth, abs=0.05e-3)


def test_incommensurate_rates_average_the_bias_away() -> None:
    data, truth = residuals(239.0, 60.0, 1 / 480, 0.2)
    assert abs(truth) < 0.02e-3
    best = refresh_hypotheses(data, 239.0, None, (0.5 / 239, 1 / 239), 24)[0]
    assert best.refresh_hz == pytest.approx(60.0, abs=0.01)
    low, high = best.quantiles_s(0.025, 0.975)
    assert abs(low) < 0.05e-3 and abs(high) < 0.05e-3


def sphere_of_rows(phase: float) -> tuple[TimingResiduals, SphereRows, float]:
    """240 fps exposing half of each frame of a 60 Hz display, the sphere a disc 14 rows tall on a
    display 100 rows tall, its centroid moving 4 rows up and down with the swing: each frame's bias
    is g averaged over the sphere's rows at their own phases. The residuals, the sphere's rows, and
    the true weighted mean bias (s)."""
    fps, rate, exposure_s, kappa = 240.0, 60.0, 1 / 480, (1 / 60) / 100
    t = np.arange(round(6.0 * fps)) / fps
    v = SPEED_PX_S * np.cos(2 * math.pi * SWING_HZ * t)
    rows = 4.0 * np.cos(4 * math.pi * SWING_HZ * t)
    u = np.linspace(-7.0, 7.0, 141)
    chord = np.sqrt(np.maximum(49.0 - u**2, 0.0))
    s = frame_phases(t, rate, phase)[:, None] - rate * kappa * (rows[:, None] + u[None, :])
    bias = exposure_bias(s - np.floor(s), exposure_s * rate) @ (chord / chord.sum()) / rate
    mean = float(v**2 @ bias / (v**2).sum())
    r = -v * (bias - mean) + NOISE_PX * np.random.default_rng(3).standard_normal(t.size)
    residuals = TimingResiduals(t, r, v, np.arange(t.size), 1.0 / fps, rows, 3.5)
    return residuals, SphereRows(rows - rows.mean(), 3.5, 0.0, (0.0, 0.0)), mean


@pytest.mark.parametrize("phase", [0.0, 0.13, 0.3, 0.62, 0.87])
def test_a_sphere_whose_rows_switch_one_after_another_keeps_its_bias_in_range(phase: float) -> None:
    data, rows, truth = sphere_of_rows(phase)
    low, high = refresh_hypotheses(data, 240.0, 60.0, (1 / 480, 1 / 480), 24, rows)[0].range_s(0.005, 0.995)
    assert low <= truth <= high
    assert high - low <= (1 / 240 - 1 / 480) + 1e-6  # no wider than every phase of a point allows


def test_a_point_model_misplaces_a_sphere_of_rows() -> None:
    # The defect the rows mend: taken as switching at one instant, the sphere's timing places the
    # switch with confidence, and its bias is read about twice what the film has.
    data, _, truth = sphere_of_rows(0.13)
    low, high = refresh_hypotheses(data, 240.0, 60.0, (1 / 480, 1 / 480), 24)[0].range_s(0.005, 0.995)
    assert not low <= truth <= high
