"""How far a rendered image is from a reference render: the seeds' Lab metric, SSIM and DSSIM, PSNR.

The Lab metric is the one of Smit, van Liere and Froehlich (2010, section 5.2): blur both images
with a three-pixel Gaussian kernel, convert them to CIE Lab, and count the pixels whose Lab distance
(CIE76) exceeds 10 units, as a percentage of all pixels. The blur and the threshold keep small,
imperceptible differences from counting.

SSIM is Wang et al.'s structural similarity (2004) on the luma (ITU-R BT.601) with their constants:
an 11-pixel Gaussian window of sigma 1.5, K1 = 0.01, K2 = 0.03, averaged over the image (Schollmeyer
et al. report it); DSSIM = (1 - SSIM) / 2 (Buchacher's quality measure).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from rig.errors import RigError

LAB_THRESHOLD = 10.0
BLUR_KERNEL_PX = 3
SSIM_WINDOW_PX = 11
SSIM_SIGMA_PX = 1.5
SSIM_K1, SSIM_K2 = 0.01, 0.03
LUMA_WEIGHTS = np.array([0.299, 0.587, 0.114])


def _checked_pair(image: np.ndarray, reference: np.ndarray) -> None:
    for what, array in (("image", image), ("reference", reference)):
        if array.dtype != np.uint8 or array.ndim != 3 or array.shape[2] != 3:
            raise RigError(f"the {what} must be RGB uint8 of shape (h, w, 3), got {array.dtype} {array.shape}")
    if image.shape != reference.shape:
        raise RigError(f"image {image.shape} and reference {reference.shape} differ in size; compare equal sizes")


def lab_error_percent(image: np.ndarray, reference: np.ndarray, threshold: float = LAB_THRESHOLD) -> float:
    """Percentage of pixels whose CIE Lab distance exceeds `threshold` after a 3-pixel Gaussian blur.

    Both are RGB uint8 (h, w, 3) in sRGB.
    """
    _checked_pair(image, reference)
    lab = [
        cv2.cvtColor(
            cv2.GaussianBlur(im, (BLUR_KERNEL_PX, BLUR_KERNEL_PX), 0).astype(np.float32) / 255.0, cv2.COLOR_RGB2Lab
        ).astype(np.float64)
        for im in (image, reference)
    ]
    distance = np.linalg.norm(lab[0] - lab[1], axis=2)
    return float(100.0 * np.mean(distance > threshold))


def psnr_db(image: np.ndarray, reference: np.ndarray) -> float:
    """Peak signal-to-noise ratio of `image` against `reference` (RGB uint8), in dB; inf if equal."""
    _checked_pair(image, reference)
    mse = float(np.mean((image.astype(np.float64) - reference.astype(np.float64)) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(255.0**2 / mse)


def ssim(image: np.ndarray, reference: np.ndarray) -> float:
    """Mean structural similarity of the two images' luma (RGB uint8): 1 when equal."""
    _checked_pair(image, reference)
    x, y = (im.astype(np.float64) @ LUMA_WEIGHTS for im in (image, reference))

    def local_mean(a: np.ndarray) -> np.ndarray:
        return cv2.GaussianBlur(a, (SSIM_WINDOW_PX, SSIM_WINDOW_PX), SSIM_SIGMA_PX, borderType=cv2.BORDER_REFLECT)

    c1, c2 = (SSIM_K1 * 255.0) ** 2, (SSIM_K2 * 255.0) ** 2
    mx, my = local_mean(x), local_mean(y)
    vx, vy, cov = local_mean(x * x) - mx**2, local_mean(y * y) - my**2, local_mean(x * y) - mx * my
    index = ((2 * mx * my + c1) * (2 * cov + c2)) / ((mx**2 + my**2 + c1) * (vx + vy + c2))
    return float(index.mean())


def dssim(image: np.ndarray, reference: np.ndarray) -> float:
    """Structural dissimilarity, (1 - SSIM) / 2: 0 when equal."""
    return (1.0 - ssim(image, reference)) / 2.0
