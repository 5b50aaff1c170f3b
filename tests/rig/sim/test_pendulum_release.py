"""A pendulum held at rest and let go during the run, against the free pendulum it becomes."""

import math

import numpy as np
import pytest

from rig.errors import ConfigError
from rig.sim.layout import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

RELEASE_S = 1.7


def test_held_pendulum_rests_exactly_at_its_amplitude_until_the_release() -> None:
    pendulum = Pendulum(PendulumConfig(amplitude_deg=25.0, release_s=RELEASE_S), t_end=4.0, t_start=-0.5)
    assert pendulum.t_release == RELEASE_S
    held = np.linspace(-0.5, RELEASE_S, 301)
    np.testing.assert_array_equal(pendulum.angle(held), math.radians(25.0))
    np.testing.assert_array_equal(pendulum.angular_velocity(held), 0.0)
    # and it moves, towards -x, right after
    assert pendulum.angular_velocity(RELEASE_S + 0.01) < -0.01
    assert pendulum.angle(RELEASE_S + 0.01) < math.radians(25.0)


@pytest.mark.parametrize("quality", [math.inf, 30.0])
def test_after_the_release_the_motion_is_a_free_release_shifted_in_time(quality: float) -> None:
    held = Pendulum(PendulumConfig(amplitude_deg=30.0, quality=quality, release_s=RELEASE_S), t_end=RELEASE_S + 5.0)
    free = Pendulum(PendulumConfig(amplitude_deg=30.0, quality=quality), t_end=5.0)
    since = np.linspace(0.0, 5.0, 2001)
    np.testing.assert_allclose(held.angle(RELEASE_S + since), free.angle(since), rtol=0, atol=1e-9)
    np.testing.assert_allclose(held.angular_velocity(RELEASE_S + since), free.angular_velocity(since), rtol=0, atol=1e-8)


def test_a_release_before_the_window_swings_from_it() -> None:
    held = Pendulum(PendulumConfig(release_s=-2.0), t_end=3.0, t_start=0.0)
    free = Pendulum(PendulumConfig(), t_end=5.0)
    t = np.linspace(0.0, 3.0, 301)
    np.testing.assert_allclose(held.angle(t), free.angle(t + 2.0), rtol=0, atol=1e-9)


def test_a_release_after_the_window_holds_it_throughout() -> None:
    pendulum = Pendulum(PendulumConfig(release_s=10.0), t_end=2.0)
    np.testing.assert_array_equal(pendulum.angle(np.array([0.0, 1.0, 2.0])), math.radians(20.0))
    assert pendulum.led_position(1.0)[0] == pytest.approx(pendulum.length_m * math.sin(math.radians(20.0)), rel=1e-15)


def test_held_shapes_follow_the_time_shape() -> None:
    pendulum = Pendulum(PendulumConfig(release_s=0.5), t_end=1.0)
    assert pendulum.angle(0.25).shape == ()
    assert pendulum.angle(0.75).shape == ()
    assert pendulum.sensor_pose(np.full((2, 3), 0.25))[1].shape == (2, 3, 4)
    assert pendulum.angle(np.array([])).shape == (0,)


def test_the_layout_frames_the_held_led_inside_its_roi() -> None:
    pendulum = Pendulum(PendulumConfig(amplitude_deg=35.0, release_s=1.0), t_end=3.0)
    layout = make_layout(pendulum, CameraConfig(width=320, height=240), DisplayConfig(width=160, height=120))
    x, y, w, h = layout.led_roi
    pixels = layout.led_pixels(pendulum.led_position(np.linspace(0.0, 3.0, 601)))
    assert np.all((pixels[:, 0] > x) & (pixels[:, 0] < x + w) & (pixels[:, 1] > y) & (pixels[:, 1] < y + h))
    # the held LED sits at the right end of the swing
    assert pixels[0, 0] == pytest.approx(pixels[:, 0].max())


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(release_s=1.0, phase_deg=90.0), "release_s and phase_deg exclude each other"),
        (dict(release_s=math.nan), "pendulum.release_s must be a number of seconds from -3600 to 3600, got nan"),
        (dict(release_s=math.inf), "pendulum.release_s must be a number of seconds from -3600 to 3600, got inf"),
    ],
)
def test_bad_releases_are_rejected(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        PendulumConfig(**kwargs)
