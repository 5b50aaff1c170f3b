"""The image-error figures the warp is judged by: the seeds' blurred Lab threshold, SSIM and DSSIM, PSNR."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rig.errors import RigError
from rig.render.image_error import dssim, lab_error_percent, psnr_db, ssim


def grey(value: int, size=(40, 50)) -> np.ndarray:
    return np.full((*size, 3), value, dtype=np.uint8)


def test_identical_images_have_no_error_and_infinite_psnr():
    image = np.random.default_rng(0).integers(0, 256, (40, 50, 3), dtype=np.uint8)
    assert lab_error_percent(image, image) == 0.0
    assert psnr_db(image, image) == math.inf


def test_a_small_uniform_difference_is_below_the_threshold_and_a_large_one_above():
    # sRGB 128 and 136 differ by about 3 Lab units; black and white by 100
    assert lab_error_percent(grey(128), grey(136)) == 0.0
    assert lab_error_percent(grey(0), grey(255)) == 100.0


def test_the_error_is_the_share_of_differing_pixels_after_a_three_pixel_blur():
    reference = grey(0, (40, 40))
    image = reference.copy()
    image[:, :10] = 255  # ten of forty columns; the blur spills a quarter of white into the eleventh
    assert lab_error_percent(image, reference) == pytest.approx(100 * 11 / 40)
    lone = reference.copy()
    lone[20, 20] = 60  # one dim pixel: blurred to about a quarter of itself, under the threshold
    assert lab_error_percent(lone, reference) == 0.0


def test_psnr_of_a_known_error():
    reference = grey(100)
    image = grey(110)
    assert psnr_db(image, reference) == pytest.approx(10 * math.log10(255**2 / 100))


def test_images_must_match_in_size_and_type():
    with pytest.raises(RigError, match="differ in size"):
        lab_error_percent(grey(0, (10, 10)), grey(0, (10, 12)))
    with pytest.raises(RigError, match="RGB uint8"):
        psnr_db(grey(0).astype(np.float32), grey(0))


def test_ssim_is_one_for_equal_images_and_dssim_zero():
    image = np.random.default_rng(1).integers(0, 256, (40, 50, 3), dtype=np.uint8)
    assert ssim(image, image) == pytest.approx(1.0, abs=1e-12)
    assert dssim(image, image) == pytest.approx(0.0, abs=1e-12)


def test_ssim_of_a_uniform_shift_is_its_luminance_term():
    """Flat images have no variance: SSIM is the luminance comparison (2 mx my + C1) / (mx^2 + my^2 + C1)."""
    c1 = (0.01 * 255) ** 2
    expected = (2 * 100 * 150 + c1) / (100**2 + 150**2 + c1)
    assert ssim(grey(100), grey(150)) == pytest.approx(expected, rel=1e-9)
    assert dssim(grey(100), grey(150)) == pytest.approx((1 - expected) / 2, rel=1e-9)


def test_noise_lowers_ssim_more_than_a_small_brightness_change():
    rng = np.random.default_rng(2)
    reference = np.clip(rng.normal(128, 40, (60, 60, 3)), 0, 255).astype(np.uint8)
    brighter = np.clip(reference.astype(int) + 5, 0, 255).astype(np.uint8)
    noisy = np.clip(reference.astype(int) + rng.normal(0, 40, reference.shape), 0, 255).astype(np.uint8)
    assert ssim(brighter, reference) > 0.99 > 0.8 > ssim(noisy, reference)
    assert 0.0 < dssim(brighter, reference) < dssim(noisy, reference) <= 1.0
