"""The misfit of every phase, exposure and row slope of one refresh rate, by folding the frames.

For a refresh rate f, a row slope m (``analysis.sampling.rows``), an exposure e (in refreshes) and a
phase phi, every frame's bias is b_n = G(frac(f (t_n - shift_n) + phi)) / f, t_n its frame time, G the exposure's bias
g smeared over the sphere's rows by f m and shift_n the time its centroid row moves its phase
(``analysis.sampling.rows``), and the sphere's residuals should read r_n = -v_n (b_n - mean b)
(``analysis.sampling.residuals``).

Frames are folded by the phase of their frame time, frac(f t_n), into bins: every phi is then a
circular shift, and the misfit over all phases takes a few FFTs per (m, e). A bin's frames are
shifted from it by shift_n, distributed over the frames as the slope's kernel says, so its model is
G smeared once more by that distribution (``analysis.sampling.rows``).

The sphere's double images (its elongation along its motion, in frames whose exposure holds a
switch) are not fitted: the tracker's moments do not measure them linearly (the fainter image of two
far apart falls partly outside the blob's support; on simulated films the elongation read 0.2 to
1.1 times what the exposure's images give), and with the row slope free they placed the switch
inside the exposure on films where it lay outside, an interval missing the truth by 0.3 ms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.sampling.model import exposure_bias
from analysis.sampling.residuals import TimingResiduals
from analysis.sampling.rows import SphereRows, disc_kernel, shift_kernel

PHASE_BINS = 512


class Folding:
    """The residuals' sums per phase bin at a refresh rate, the frames at ``times`` (their frame
    times; residuals.t by default): W = sum v^2 and X = sum v r, and their spectra."""

    def __init__(self, residuals: TimingResiduals, refresh_hz: float, bins: int, times: np.ndarray | None = None) -> None:
        phase = refresh_hz * (residuals.t if times is None else times)
        self.bins = bins
        self.index = ((phase - np.floor(phase)) * bins).astype(np.int64) % bins
        self.w = np.bincount(self.index, residuals.v**2, bins)
        self.x = np.bincount(self.index, residuals.v * residuals.r, bins)
        self.w_spectrum = np.fft.rfft(self.w)
        self.x_spectrum = np.fft.rfft(self.x)

    def explained(self) -> float:
        """The sum of squares a free timing offset per bin explains."""
        used = self.w > 0
        return float(np.sum(self.x[used] ** 2 / self.w[used]))


def kernel_spectrum(residuals: TimingResiduals, rate: float, rows: SphereRows, slope: float, bins: int = PHASE_BINS) -> np.ndarray:
    """The spectrum of what a slope (s per row) smears the model by at ``rate`` (see
    ``analysis.sampling.rows``): the sphere's rows, and the frames' shifts weighted as the timing
    weighs them, by v^2."""
    radius = rate * abs(slope) * rows.radius_px
    shifts = shift_kernel(rate * rows.shifts(slope), residuals.v**2, bins)
    return np.fft.rfft(disc_kernel(radius, bins)) * np.fft.rfft(shifts)


def bias_spectrum(rate: float, exposures_s: np.ndarray, bins: int = PHASE_BINS) -> np.ndarray:
    """The spectrum along the phase bins of the bias (s) of ``rate`` per exposure, for a point."""
    centres = (np.arange(bins) + 0.5) / bins
    return np.fft.rfft(exposure_bias(centres[None, :], exposures_s[:, None] * rate) / rate, axis=1)


def bias_table(rate: float, exposures_s: np.ndarray, bins: int = PHASE_BINS, kernel: np.ndarray | None = None) -> np.ndarray:
    """The bias (s) of ``rate`` per exposure and phase bin, smeared by a slope's ``kernel`` spectrum
    (none by default)."""
    spectrum = bias_spectrum(rate, exposures_s, bins)
    return np.fft.irfft(spectrum if kernel is None else spectrum * kernel, bins, axis=1)


@dataclass(frozen=True)
class Fit:
    """One rate's timing misfits over (slopes, exposures, phases) and each hypothesis's weighted mean
    bias (s); the slopes (s per row) and the frames folded."""

    rate: float
    slopes: np.ndarray
    folding: Folding
    timing: np.ndarray
    mean: np.ndarray


def fit_one(residuals: TimingResiduals, spectrum: np.ndarray, folding: Folding) -> tuple[np.ndarray, np.ndarray]:
    """(misfit, mean bias) of the bias table whose ``spectrum`` (exposures, bins / 2 + 1) is given, for
    every exposure and phase j / bins, the frames folded by ``folding``: each phase a circular shift
    of the per-bin model, so a few FFTs."""
    bins = folding.bins

    def correlate(values: np.ndarray, table: np.ndarray) -> np.ndarray:
        return np.fft.irfft(np.conj(values)[None, :] * table, bins, axis=1)

    table = np.fft.irfft(spectrum, bins, axis=1)
    total_w, total_x = folding.w.sum(), folding.x.sum()
    mean = correlate(folding.w_spectrum, spectrum) / max(total_w, 1e-300)
    squares = float(residuals.r @ residuals.r)
    misfit = (
        squares
        + 2 * correlate(folding.x_spectrum, spectrum)
        - 2 * mean * total_x
        + correlate(folding.w_spectrum, np.fft.rfft(table**2, axis=1))
        - mean**2 * total_w
    )
    return misfit, mean


def fit(
    residuals: TimingResiduals, rate: float, exposures_s: np.ndarray, rows: SphereRows | None, slopes: np.ndarray | None = None
) -> Fit:
    """The misfits of ``rate`` over the row ``slopes`` (by default the coarse grid the sphere's rows
    allow; one, 0, without them), every exposure and every phase."""
    if slopes is None:
        slopes = rows.slopes(rate) if rows is not None else np.zeros(1)
    folding = Folding(residuals, rate, PHASE_BINS, rows.frame_times(residuals.t) if rows is not None else None)
    point = bias_spectrum(rate, exposures_s)
    misfits, means = [], []
    for slope in slopes:
        spectrum = point * kernel_spectrum(residuals, rate, rows, float(slope)) if rows is not None else point
        misfit, mean = fit_one(residuals, spectrum, folding)
        misfits.append(misfit)
        means.append(mean)
    return Fit(rate, slopes, folding, np.stack(misfits), np.stack(means))


def frame_biases(residuals: TimingResiduals, fitted: Fit, rows: SphereRows | None, at: tuple[int, int, int], exposure_s: float) -> np.ndarray:
    """Per frame, the bias (s) of the hypothesis ``at`` = (slope, exposure, phase) indices of
    ``fitted``, at ``exposure_s``: its phase bin's."""
    slope_index, _, phase_index = at
    kernel = kernel_spectrum(residuals, fitted.rate, rows, float(fitted.slopes[slope_index])) if rows is not None else None
    table = bias_table(fitted.rate, np.array([exposure_s]), PHASE_BINS, kernel)
    return table[0][(fitted.folding.index + phase_index) % PHASE_BINS]
