"""The true effective latency recovers known delays of a displayed signal."""

import numpy as np
import pytest

from rig.sim.truth import effective_latency, shown_signal

PERIOD = 1.0


def led_x(t: np.ndarray) -> np.ndarray:
    return 0.1 * np.sin(2 * np.pi * t / PERIOD) * np.exp(-0.05 * t)


def test_shown_signal_holds_each_value_until_the_next_switch() -> None:
    switches = np.array([1.0, 2.0, 3.0])
    values = np.array([10.0, 20.0, 30.0])
    shown = shown_signal(switches, values, np.array([0.5, 1.0, 1.5, 2.999, 3.0, 9.0]))
    assert np.isnan(shown[0])
    np.testing.assert_array_equal(shown[1:], [10.0, 10.0, 20.0, 30.0, 30.0])


@pytest.mark.parametrize("delay", [0.0, 0.012, 0.0437, 0.120, -0.020])
def test_continuous_delay_is_recovered(delay: float) -> None:
    switches = np.arange(-1.0, 6.0, 1e-4)
    shown_x = led_x(switches - delay)
    tau = effective_latency(switches, shown_x, led_x, (0.0, 5.0), PERIOD)
    assert tau == pytest.approx(delay + 0.5e-4, abs=2e-6)


@pytest.mark.parametrize("refresh_hz", [60.0, 144.0])
def test_sample_and_hold_adds_half_a_refresh(refresh_hz: float) -> None:
    delay = 0.030
    switches = np.arange(-1.0, 6.0, 1 / refresh_hz)
    shown_x = led_x(switches - delay)
    tau = effective_latency(switches, shown_x, led_x, (0.0, 5.0), PERIOD, guess_s=0.04)
    assert tau == pytest.approx(delay + 0.5 / refresh_hz, abs=5e-5)


def test_a_delay_far_from_the_guess_within_half_a_period_is_found() -> None:
    switches = np.arange(-1.0, 6.0, 1e-3)
    tau = effective_latency(switches, led_x(switches - 0.3), led_x, (0.0, 5.0), PERIOD, guess_s=0.0)
    assert tau == pytest.approx(0.3005, abs=1e-5)
