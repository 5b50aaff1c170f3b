"""The camera's exposure from the LED's blur: the variance along its motion grows as (v E)^2 / 12."""

import math

import numpy as np
import pytest

from analysis.sampling.exposure import exposure_from_blur, given_exposure, saturation_excess
from analysis.blobs import Track

FPS = 120.0


def led_track(exposure_s: float, level: float, seconds: float = 4.0, noise: float = 0.05) -> Track:
    """An LED swinging along x (and a little along y) with the moments a blur of ``exposure_s`` gives."""
    t = np.arange(round(seconds * FPS)) / FPS
    x = 100 + 120 * np.sin(2 * math.pi * t)
    y = 50 + 10 * np.cos(4 * math.pi * t)
    vx, vy = np.gradient(x, t), np.gradient(y, t)
    speed = np.hypot(vx, vy)
    ux, uy = vx / np.maximum(speed, 1e-9), vy / np.maximum(speed, 1e-9)
    spot, smear = 3.0, (speed * exposure_s) ** 2 / 12
    rng = np.random.default_rng(1)
    sxx = spot + smear * ux * ux + noise * rng.standard_normal(t.size)
    syy = spot + smear * uy * uy + noise * rng.standard_normal(t.size)
    sxy = smear * ux * uy
    valid = np.ones(t.size, dtype=bool)
    return Track(
        t, x, y, valid, np.full(t.size, 200.0), np.zeros(t.size, dtype=bool), np.full(t.size, level),
        np.full(t.size, 5000.0), np.column_stack([sxx, syy, sxy]),
    )  # fmt: skip


@pytest.mark.parametrize("exposure_s", [1 / 480, 1 / 240, 1 / 120])
def test_an_unsaturated_led_gives_its_exposure(exposure_s: float) -> None:
    exposure = exposure_from_blur(led_track(exposure_s, level=180.0), 1 / FPS)
    assert exposure.source == "LED blur"
    assert exposure.estimate_s == pytest.approx(exposure_s, rel=0.03)
    assert exposure.low_s <= exposure_s <= exposure.high_s
    assert exposure.high_s <= 1 / FPS


def test_a_saturated_led_allows_a_shorter_exposure_than_its_blur_says() -> None:
    linear = exposure_from_blur(led_track(1 / 480, level=180.0), 1 / FPS)
    saturated = exposure_from_blur(led_track(1 / 480, level=255.0), 1 / FPS)
    assert saturated.low_s < linear.low_s
    assert saturated.estimate_s / saturated.low_s >= saturation_excess(1.0)


def test_the_excess_of_saturation_fades_for_a_long_smear() -> None:
    assert saturation_excess(0.5) > 1.4
    assert saturation_excess(20.0) < 1.1


def test_an_led_too_slow_to_blur_leaves_the_exposure_unknown() -> None:
    exposure = exposure_from_blur(led_track(1e-6, level=180.0), 1 / FPS)
    assert exposure.source == "unknown"
    assert (exposure.low_s, exposure.high_s) == (0.0, 1 / FPS)


def test_a_given_exposure_is_at_most_the_frame_interval() -> None:
    assert given_exposure(0.02, 1 / FPS).high_s == pytest.approx(1 / FPS)
    assert given_exposure(0.002, 1 / FPS).low_s == 0.002
