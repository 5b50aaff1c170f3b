"""The simulated pendulum against the physics it claims: periods, damping, energy, geometry."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import ellipk

from rig.errors import ConfigError
from rig.sim.pendulum import Pendulum, PendulumConfig

G = 9.80665


def _refined_roots(f, df, t_grid):
    """Times where f crosses zero, bracketed on t_grid and polished by Newton steps on (f, df)."""
    values = f(t_grid)
    left = np.nonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)[0]
    roots = t_grid[left] - values[left] / df(t_grid[left])
    for _ in range(4):
        roots = roots - f(roots) / df(roots)
    return roots


def _measured_period(pendulum: Pendulum, periods: int) -> float:
    """The mean time between zero crossings in the same direction, from the simulated motion."""
    t_grid = np.linspace(pendulum.t_start, pendulum.t_end, 100 * periods + 1)
    crossings = _refined_roots(pendulum.angle, pendulum.angular_velocity, t_grid)
    assert crossings.size >= 2 * periods - 1
    return (crossings[-1] - crossings[0]) / ((crossings.size - 1) / 2)


def _angular_acceleration(pendulum: Pendulum, t: np.ndarray) -> np.ndarray:
    omega0 = pendulum.omega0
    damping = omega0 / pendulum.config.quality
    return -(omega0**2) * np.sin(pendulum.angle(t)) - damping * pendulum.angular_velocity(t)


def _energy_per_mass(pendulum: Pendulum, t: np.ndarray) -> np.ndarray:
    length = pendulum.length_m
    kinetic = 0.5 * (length * pendulum.angular_velocity(t)) ** 2
    potential = pendulum.config.g * length * (1.0 - np.cos(pendulum.angle(t)))
    return kinetic + potential


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v rotated by unit quaternions q (w, x, y, z): v + 2w (u x v) + 2 u x (u x v)."""
    w, u = q[..., :1], q[..., 1:]
    uv = np.cross(u, v)
    return v + 2.0 * w * uv + 2.0 * np.cross(u, uv)


def test_small_angle_period_matches_two_pi_root_l_over_g():
    length = 0.8
    pendulum = Pendulum(PendulumConfig(period_s=None, length_m=length, amplitude_deg=0.5, quality=1e6), 20.0)
    expected = 2.0 * math.pi * math.sqrt(length / G)
    assert _measured_period(pendulum, 10) == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("amplitude_deg", [30.0, 45.0])
def test_large_amplitude_period_matches_elliptic_integral(amplitude_deg):
    length = 0.5
    config = PendulumConfig(period_s=None, length_m=length, amplitude_deg=amplitude_deg, quality=math.inf)
    pendulum = Pendulum(config, 12.0)
    expected = 4.0 * math.sqrt(length / G) * ellipk(math.sin(math.radians(amplitude_deg) / 2.0) ** 2)
    measured = _measured_period(pendulum, 8)
    assert measured == pytest.approx(expected, rel=5e-4)
    assert pendulum.period_s == pytest.approx(expected, rel=1e-12)
    # The amplitude correction is large enough that the small-angle formula would fail this test.
    assert abs(measured / pendulum.config.small_angle_period_s - 1.0) > 0.01


def test_amplitude_decays_at_the_rate_q_implies():
    quality = 50.0
    pendulum = Pendulum(PendulumConfig(period_s=1.0, amplitude_deg=2.0, quality=quality), 12.0)
    t_grid = np.linspace(0.0, 12.0, 1201)
    turning = _refined_roots(
        pendulum.angular_velocity, lambda t: _angular_acceleration(pendulum, t), t_grid
    )
    assert turning.size >= 20
    slope = np.polyfit(turning, np.log(np.abs(pendulum.angle(turning))), 1)[0]
    assert -slope == pytest.approx(pendulum.omega0 / (2.0 * quality), rel=0.01)


def test_energy_is_conserved_without_damping():
    pendulum = Pendulum(PendulumConfig(amplitude_deg=45.0, quality=math.inf), 20.0)
    energy = _energy_per_mass(pendulum, np.linspace(0.0, 20.0, 20001))
    assert np.max(np.abs(energy / energy[0] - 1.0)) < 1e-8


@settings(max_examples=15, deadline=None)
@given(
    amplitude_deg=st.floats(0.5, 45.0),
    # Below Q ~ 5 the swing dies out within the window, until the energy is at the level of the
    # integrator's absolute tolerance and its rounding looks like small increases.
    quality=st.floats(5.0, 1e4),
    phase_deg=st.floats(0.0, 359.0),
)
def test_damped_energy_never_increases(amplitude_deg, quality, phase_deg):
    config = PendulumConfig(amplitude_deg=amplitude_deg, quality=quality, phase_deg=phase_deg)
    pendulum = Pendulum(config, 3.0)
    energy = _energy_per_mass(pendulum, np.linspace(0.0, 3.0, 3001))
    assert np.all(np.diff(energy) <= 1e-10 * energy[0])


def test_period_and_length_configs_give_the_same_motion():
    period = 1.3
    by_period = Pendulum(PendulumConfig(period_s=period), 5.0)
    by_length = Pendulum(PendulumConfig(period_s=None, length_m=G * (period / (2.0 * math.pi)) ** 2), 5.0)
    assert by_period.length_m == pytest.approx(by_length.length_m, rel=1e-15)
    assert by_period.config.small_angle_period_s == pytest.approx(period, rel=1e-14)
    t = np.linspace(0.0, 5.0, 501)
    np.testing.assert_allclose(by_period.angle(t), by_length.angle(t), rtol=0, atol=1e-10)


@pytest.mark.parametrize(
    "phase_deg, angle_fraction, velocity_sign",
    [(0.0, 1.0, 0.0), (90.0, 0.0, -1.0), (180.0, -1.0, 0.0), (270.0, 0.0, 1.0)],
)
def test_phase_says_where_in_the_swing_the_window_starts(phase_deg, angle_fraction, velocity_sign):
    config = PendulumConfig(amplitude_deg=30.0, quality=math.inf, phase_deg=phase_deg)
    pendulum = Pendulum(config, t_end=12.0, t_start=10.0)
    amplitude = math.radians(30.0)
    assert pendulum.angle(10.0) == pytest.approx(angle_fraction * amplitude, abs=1e-9)
    velocity = pendulum.angular_velocity(10.0)
    if velocity_sign == 0.0:
        assert velocity == pytest.approx(0.0, abs=1e-9)
    else:
        assert np.sign(velocity) == velocity_sign


def test_led_position_and_sensor_pose_are_consistent():
    pivot = (0.1, 1.2, -0.3)
    pendulum = Pendulum(PendulumConfig(amplitude_deg=40.0, pivot=pivot), 2.0)
    t = np.linspace(0.0, 2.0, 401)
    led = pendulum.led_position(t)
    positions, orientations = pendulum.sensor_pose(t)
    np.testing.assert_array_equal(led, positions)
    np.testing.assert_allclose(np.linalg.norm(orientations, axis=1), 1.0, atol=1e-15)
    arm = positions - np.asarray(pivot)
    np.testing.assert_allclose(np.linalg.norm(arm, axis=1), pendulum.length_m, rtol=1e-14)
    body_down = np.array([0.0, -1.0, 0.0])
    np.testing.assert_allclose(_rotate(orientations, body_down), arm / pendulum.length_m, atol=1e-14)
    theta = pendulum.angle(t)
    assert np.all(np.sign(arm[:, 0]) == np.sign(theta))
    np.testing.assert_array_equal(arm[:, 2], 0.0)


def test_output_shapes_follow_the_time_shape():
    pendulum = Pendulum(PendulumConfig(), 1.0)
    assert pendulum.angle(0.5).shape == ()
    assert pendulum.led_position(0.5).shape == (3,)
    positions, orientations = pendulum.sensor_pose(np.full((2, 5), 0.25))
    assert positions.shape == (2, 5, 3)
    assert orientations.shape == (2, 5, 4)
    assert pendulum.angle(np.array([])).shape == (0,)


@pytest.mark.parametrize("t", [-1e-9, 1.0 + 1e-9, math.nan])
def test_times_outside_the_window_raise(t):
    pendulum = Pendulum(PendulumConfig(), 1.0)
    with pytest.raises(ConfigError, match="outside the simulated window"):
        pendulum.angle(np.array([0.5, t]))


def test_window_ends_are_inside():
    pendulum = Pendulum(PendulumConfig(), t_end=3.0, t_start=1.0)
    assert pendulum.angle(np.array([1.0, 3.0])).shape == (2,)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(period_s=None), "exactly one of period_s and length_m"),
        (dict(period_s=1.0, length_m=0.25), "exactly one of period_s and length_m"),
        (dict(period_s=-1.0), "pendulum.period_s must be a positive number of seconds from 0.2 to 20, got -1.0"),
        (dict(period_s=None, length_m=math.nan), "pendulum.length_m must be a positive number of metres from 0.01 to 100, got nan"),
        (dict(period_s=math.inf), "pendulum.period_s must be a positive number of seconds from 0.2 to 20, got inf"),
        (dict(g=0.0), "pendulum.g must be a positive number of m/s\\^2 at most 100, got 0.0"),
        (dict(amplitude_deg=0.0), "pendulum.amplitude_deg must be a positive number of degrees at most 45, got 0.0"),
        (dict(amplitude_deg=45.1), "pendulum.amplitude_deg must be a positive number of degrees at most 45, got 45.1"),
        (dict(amplitude_deg=math.nan), "pendulum.amplitude_deg must be a positive number of degrees at most 45, got nan"),
        (dict(quality=0.0), "pendulum.quality must be a positive number, got 0.0"),
        (dict(quality=math.nan), "pendulum.quality must be a positive number, got nan"),
        (dict(phase_deg=360.0), "pendulum.phase_deg must be zero or a positive number of degrees below 360, got 360.0"),
        (dict(phase_deg=-1.0), "pendulum.phase_deg must be zero or a positive number of degrees below 360, got -1.0"),
        (dict(pivot=(0.0, 0.0)), "pivot must be three finite coordinates"),
    ],
)
def test_config_rejects_bad_values(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        PendulumConfig(**kwargs)


@pytest.mark.parametrize("t_start, t_end", [(0.0, 0.0), (1.0, 0.5), (0.0, math.inf)])
def test_pendulum_rejects_bad_windows(t_start, t_end):
    with pytest.raises(ConfigError, match="t_end > t_start"):
        Pendulum(PendulumConfig(), t_end=t_end, t_start=t_start)


def test_config_error_is_a_value_error():
    with pytest.raises(ValueError):
        PendulumConfig(amplitude_deg=90.0)


def test_a_lookback_widens_the_window_without_moving_the_swing():
    config = PendulumConfig(period_s=20.0)
    plain = Pendulum(config, t_end=5.0, t_start=-1.5)
    widened = Pendulum(config, t_end=5.0, t_start=-1.5, lookback_s=20.0)
    t = np.linspace(-1.5, 5.0, 50)
    np.testing.assert_array_equal(widened.angle(t), plain.angle(t))
    assert widened.angle(np.array([-21.5]))[0] == pytest.approx(math.radians(config.amplitude_deg))
    with pytest.raises(ConfigError, match="outside the simulated window"):
        widened.angle(np.array([-21.6]))
