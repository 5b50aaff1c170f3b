"""The bench's layout: where the LED's swing and the display panel sit in the camera's frame."""

import numpy as np
import pytest

from rig.errors import ConfigError
from rig.sim.layout import make_layout
from rig.sim.placement import LAYOUTS, placement
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

CAMERA = CameraConfig(width=320, height=240)
DISPLAY = DisplayConfig(width=160, height=120)


@pytest.fixture(scope="module")
def pendulum() -> Pendulum:
    return Pendulum(PendulumConfig(), t_end=3.0)


def _swing(pendulum: Pendulum) -> np.ndarray:
    return pendulum.led_position(np.linspace(0.0, 3.0, 601))


def test_the_default_is_the_left_and_right_halves(pendulum: Pendulum) -> None:
    layout = make_layout(pendulum, CAMERA, DISPLAY)
    spelled = make_layout(pendulum, CAMERA, DISPLAY, LAYOUTS["side-by-side"])
    assert (layout.panel, layout.led_roi, layout.sphere_roi, layout.px_per_m, layout.led_centre_px) == (
        spelled.panel, spelled.led_roi, spelled.sphere_roi, spelled.px_per_m, spelled.led_centre_px,
    )  # fmt: skip
    led = layout.led_pixels(_swing(pendulum))
    assert led[:, 0].max() < 160 < layout.panel[0]
    assert led[:, 0].mean() == pytest.approx(80.0, abs=1.0)
    assert layout.panel[1] + layout.panel[3] / 2 == pytest.approx(120.0, abs=1.0)


@pytest.mark.parametrize(("name", "sign"), [("led-above", 1.0), ("led-below", -1.0)])
def test_the_led_sits_35_percent_of_the_height_above_or_below_the_sphere(pendulum: Pendulum, name: str, sign: float) -> None:
    layout = make_layout(pendulum, CAMERA, DISPLAY, name)
    led_row, sphere_row = layout.mean_rows(_swing(pendulum))
    assert sign * (sphere_row - led_row) == pytest.approx(0.35, abs=0.02)
    led = layout.led_pixels(_swing(pendulum))
    sphere = layout.panel_pixels(_swing(pendulum))
    for points, (x, y, w, h) in ((led, layout.led_roi), (sphere, layout.sphere_roi)):
        assert np.all((points[:, 0] > x) & (points[:, 0] < x + w) & (points[:, 1] > y) & (points[:, 1] < y + h))


def test_an_explicit_layout_places_both_where_it_says(pendulum: Pendulum) -> None:
    layout = make_layout(pendulum, CAMERA, DISPLAY, "0.5,0.2,0.5/0.5,0.7,0.5")
    led = layout.led_pixels(_swing(pendulum))
    assert np.ptp(led[:, 0]) == pytest.approx(0.5 * 320, rel=0.01)
    assert led[:, 0].mean() == pytest.approx(160.0, abs=1.0)
    x, y, w, h = layout.panel
    assert (w, x + w / 2, y + h / 2) == (160, pytest.approx(160.0, abs=1.0), pytest.approx(168.0, abs=1.0))
    assert placement("0.5,0.2,0.5/0.5,0.7,0.5").led == (0.5, 0.2, 0.5)


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("diagonal", "a bench layout is one of"),
        ("0.2,0.5,0.4", "a bench layout is one of"),
        ("0.2,0.5,0.4/0.7,0.5,1.2", "a bench layout is one of"),
        ("0.1,0.5,0.4/0.7,0.5,0.4", "LED's swing partly outside"),
        ("0.25,0.5,0.4/0.9,0.5,0.42", "display panel partly outside"),
        ("0.4,0.5,0.4/0.6,0.5,0.42", "over the display panel"),
    ],
)
def test_impossible_layouts_are_refused(pendulum: Pendulum, spec: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message) as refused:
        make_layout(pendulum, CAMERA, DISPLAY, spec)
    assert repr(spec) in str(refused.value) and "BenchLayout" not in str(refused.value)
