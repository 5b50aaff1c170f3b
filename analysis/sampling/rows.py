"""The sphere's rows: a display's scan-out reaches them one after another, and so may the camera's.

A display switches row after row from the top, so the rows of a sphere switch over a part of a
refresh, and a sphere lower down the display switches later. A rolling-shutter camera likewise
exposes each row later than the one above (``analysis.readout``). What counts for the sphere's
timing is the difference, the net slope m (s per camera row): a row u rows below the sphere's
centroid starts its exposure m u less long after its switch than the centroid's row does. With
kappa the display's scan-out time per camera row and r the camera's readout time per row,
m = kappa - r.

So each frame's bias is not g at one phase (``analysis.sampling.model``) but g averaged over the
sphere's rows, each at its own phase: g smeared by the sphere's row profile scaled by f m
(``disc_kernel``), and the centroid's phase moves as the sphere moves up and down the
frame: its phase is frac(f t_k - f m dy + phi), t_k the frame's time and dy its row less its mean.
Frames are compared with the model by the phase of their frame time alone (``frame_times``: a
sample dated by its rows, a readout given, less what the dating added), so the centroid's moves are
a distribution of shifts over the frames (``shift_kernel``), which smears the model once more: the
frames in a phase bin are, on average, that far off it. Their slow swing with the sphere's rows is
then no part of the model, as the slow errors of the tracks (a blob's shape against its position)
are none: a model that followed it would follow them too. Folded by their dated times, the frames
of a camera locked to the display would split between neighbouring bins by their rows, that is by
where the swing is, and the tracks' slow errors would read as a switch falling between them.

Neither kappa nor the true r is known: kappa is at least 0 (a display that scans top to bottom as
the camera sees it) and at most a refresh over the sphere's extent (the display is at least as tall
as the part of it the sphere covers); r lies in the range the shutter gives. The video decides
within that range (``analysis.sampling.inference`` fits m with the phase and the exposure). The
sphere's row profile is taken as a disc's (a chord per row) of the row variance the tracker
measures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# The coarse slope grid's steps move the kernel's radius, and the centroid's phase over the sphere's
# rows travel, by at most this fraction of a refresh, with at most COARSE_SLOPES steps; the fine
# grid's, around the slopes the coarse one left possible, by FINE_STEP_REFRESHES, with at most
# FINE_SLOPES steps (fewer where many exposures are tried with them, see REFINED_GRID).
COARSE_STEP_REFRESHES = 1.0 / 32
COARSE_SLOPES = 16
FINE_STEP_REFRESHES = 1.0 / 512
FINE_SLOPES = 48
# At most this many (slope, exposure) pairs are refined: 48 slopes for a given exposure, 12 for 48.
REFINED_GRID = 576
# Coarse slopes whose posterior weight is below this fraction of the largest are not refined.
NEGLIGIBLE_WEIGHT = 1e-6


@dataclass(frozen=True)
class SphereRows:
    """The sphere's rows, per used frame: offsets its centroid row less its mean (px); row_sd its
    rows' own standard deviation (px); dating_row_s the time per row its samples were dated by;
    row_time_range_s the range the camera's true time per row lies in (s)."""

    offsets: np.ndarray
    row_sd: float
    dating_row_s: float
    row_time_range_s: tuple[float, float]

    @property
    def radius_px(self) -> float:
        """The radius of the disc of the rows' variance (px)."""
        return 2.0 * self.row_sd

    @property
    def extent_px(self) -> float:
        """The rows the sphere covers over the clip (px): its travel and its own height."""
        return float(np.ptp(self.offsets)) + 2.0 * self.radius_px if self.offsets.size else 2.0 * self.radius_px

    def slopes(self, refresh_hz: float) -> np.ndarray:
        """The net slopes m (s per row) a display of this rate allows, on the coarse grid (see the
        module docstring); one slope, 0, for a sphere with no height or travel."""
        low = -self.row_time_range_s[1]
        high = 1.0 / (refresh_hz * max(self.extent_px, 1e-9)) - self.row_time_range_s[0]
        return self._grid(refresh_hz, low, high, COARSE_STEP_REFRESHES, COARSE_SLOPES)

    def refined(self, refresh_hz: float, coarse: np.ndarray, weights: np.ndarray, most: int = FINE_SLOPES) -> np.ndarray:
        """A fine grid of at most ``most`` steps over the slopes of the ``coarse`` grid whose
        posterior ``weights`` are not negligible, a coarse step beyond them either side."""
        if coarse.size < 2:
            return coarse
        kept = np.flatnonzero(weights >= NEGLIGIBLE_WEIGHT * weights.max())
        step = coarse[1] - coarse[0]
        low, high = max(coarse[kept[0]] - step, coarse[0]), min(coarse[kept[-1]] + step, coarse[-1])
        return self._grid(refresh_hz, low, high, FINE_STEP_REFRESHES, min(most, FINE_SLOPES))

    def _grid(self, refresh_hz: float, low: float, high: float, step_refreshes: float, most: int) -> np.ndarray:
        reach = max(self.radius_px, float(np.ptp(self.offsets)) / 2 if self.offsets.size else 0.0)
        steps = math.ceil(refresh_hz * (high - low) * reach / step_refreshes)
        if reach <= 0 or steps < 1:
            return np.full(1, (low + high) / 2) if reach > 0 else np.zeros(1)
        return np.linspace(low, high, min(steps, most) + 1)

    def shifts(self, slope_s: float) -> np.ndarray:
        """Per frame, by how much (s) the net slope ``slope_s`` moves the centroid's row's phase
        earlier than its frame time's."""
        return slope_s * self.offsets

    def frame_times(self, dated: np.ndarray) -> np.ndarray:
        """The frames' times (up to a constant) of samples ``dated`` by their rows."""
        return dated - self.dating_row_s * self.offsets


def disc_kernel(radius: float, bins: int) -> np.ndarray:
    """The weights on ``bins`` circular phase bins (bin 0 at 0) of a disc's rows spread over
    +-``radius`` (in refreshes): each bin's share of the semicircle sqrt(radius^2 - u^2)."""
    kernel = np.zeros(bins)
    if radius * bins < 1e-3:
        kernel[0] = 1.0
        return kernel
    reach = math.ceil(radius * bins + 0.5)
    centres = np.arange(-reach, reach + 1)
    edges = np.clip(np.append(centres - 0.5, reach + 0.5) / bins, -radius, radius)
    area = 0.5 * (edges * np.sqrt(np.maximum(radius**2 - edges**2, 0.0)) + radius**2 * np.arcsin(edges / radius))
    np.add.at(kernel, centres % bins, np.diff(area))
    return kernel / kernel.sum()


def shift_kernel(shifts: np.ndarray, weights: np.ndarray, bins: int) -> np.ndarray:
    """The weighted distribution, on ``bins`` circular phase bins (bin 0 at 0), of frames' phase
    shifts (in refreshes)."""
    index = np.rint(np.asarray(shifts) * bins).astype(np.int64) % bins
    kernel = np.bincount(index, weights, bins)
    total = kernel.sum()
    if not total > 0:
        kernel = np.zeros(bins)
        kernel[0] = 1.0
        return kernel
    return kernel / total
