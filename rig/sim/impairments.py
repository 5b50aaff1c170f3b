"""What a lab's camera may do to its film besides its rate, exposure and read noise
(`FilmImpairments`, the simulated camera's `impairments`): defocus blur, a dim LED, a mirrored
image (the LED and the sphere swapped), a bright lamp in view, a bar hiding part of a blob's path,
the sphere hidden from a fraction of frames, and a film that keeps only every n-th exposure.

They act on each 8-bit frame the sensor makes, in the order of the fields, before the frame is
recorded (`FrameImpairer`). A hidden region shows the rig's background there: the sensor's dark
level, and on the display panel the panel's black too.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from rig.sim.impairments_config import FilmImpairments, Rect

# A bar as wide as this fraction of a blob's swing, across its path a third of the way along.
OCCLUDER_FRACTION = 0.12
BRIGHT_OBJECT_SIGMA_PX = 4.0


Change = Callable[[int, np.ndarray], np.ndarray | None]


class FrameImpairer:
    """The impairments applied to each sensor frame (its index among all exposures): the film's
    frame, or None for one the film leaves out."""

    def __init__(
        self, impairments: FilmImpairments, background: np.ndarray, rois: dict[str, Rect], exposures: int, seed: int
    ) -> None:
        """`background`: the sensor's image of the rig with nothing moving in view (8-bit); `rois`:
        where the "led" and the "sphere" swing on the sensor; `exposures`: how many the sensor makes."""
        self._changes = _changes(impairments, background, rois, exposures, seed)

    def __call__(self, index: int, frame: np.ndarray) -> np.ndarray | None:
        for change in self._changes:
            changed = change(index, frame)
            if changed is None:
                return None
            frame = changed
        return frame


def _changes(impairments: FilmImpairments, background: np.ndarray, rois: dict[str, Rect], exposures: int, seed: int) -> list[Change]:
    import cv2  # here, not above: a camera's settings are read without OpenCV

    f = impairments
    changes: list[Change] = []
    if f.blur_sigma_px > 0.0:
        changes.append(lambda _, frame: cv2.GaussianBlur(frame, (0, 0), f.blur_sigma_px))
    if f.dim_led < 1.0:
        changes.append(
            lambda _, frame: np.concatenate(
                [np.rint(frame[:, : frame.shape[1] // 2] * f.dim_led).astype(np.uint8), frame[:, frame.shape[1] // 2 :]], axis=1
            )
        )
    if f.bright_object_dn > 0.0:
        spot = _bright_object(background.shape, f.bright_object_dn)
        changes.append(lambda _, frame: np.clip(frame + spot, 0, 255).astype(np.uint8))
    if f.occluded is not None:
        changes.append(_bar(background, rois[f.occluded]))
    if f.missing_fraction > 0.0:
        changes.append(_missing(background, rois["sphere"], exposures, f.missing_fraction, seed))
    if f.mirrored:
        changes.append(lambda _, frame: np.ascontiguousarray(frame[:, ::-1]))
    if f.every_nth > 1:
        changes.append(lambda index, frame: frame if index % f.every_nth == f.first_frame else None)
    return changes


def _bar(background: np.ndarray, roi: Rect) -> Change:
    """A change that hides a vertical bar across a blob's path (the background shows there)."""
    x, y, w, h = roi
    left, width = x + w // 3, max(2, round(OCCLUDER_FRACTION * w))

    def hide(_: int, frame: np.ndarray) -> np.ndarray:
        frame = frame.copy()
        frame[y : y + h, left : left + width] = background[y : y + h, left : left + width]
        return frame

    return hide


def _missing(background: np.ndarray, roi: Rect, exposures: int, fraction: float, seed: int) -> Change:
    """A change that hides the blob's whole region in `fraction` of the frames, drawn by `seed`."""
    x, y, w, h = roi
    hidden = set(np.random.default_rng(seed).choice(exposures, round(fraction * exposures), replace=False).tolist())

    def hide(index: int, frame: np.ndarray) -> np.ndarray:
        if index not in hidden:
            return frame
        frame = frame.copy()
        frame[y : y + h, x : x + w] = background[y : y + h, x : x + w]
        return frame

    return hide


def _bright_object(shape: tuple[int, ...], peak_dn: float) -> np.ndarray:
    """A static bright spot between and above the two halves, saturated like a lamp."""
    height, width = shape
    rows, cols = np.mgrid[0:height, 0:width]
    spot = peak_dn * np.exp(-((cols - width / 2) ** 2 + (rows - height / 8) ** 2) / (2 * BRIGHT_OBJECT_SIGMA_PX**2))
    return spot.astype(np.float32)
