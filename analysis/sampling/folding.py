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
from analysis.sampling.rows import SphereRows, disc_kernel, shift_kernel, smeared

PHASE_BINS = 512


class Folding:
    """The residuals' sums per phase bin at a refresh rate, the frames at ``times`` (their frame
    times; residuals.t by default): W = sum v^2 and X = sum v r."""

    def __init__(self, residuals: TimingResiduals, refresh_hz: float, bins: int, times: np.ndarray | None = None) -> None:
        phase = refresh_hz * (residuals.t if times is None else times)
        self.index = ((phase - np.floor(phase)) * bins).astype(np.int64) % bins
        self.w = np.bincount(self.index, residuals.v**2, bins)
        self.x = np.bincount(self.index, residuals.v * residuals.r, bins)

    def explained(self) -> float:
        """The sum of squares a free timing offset per bin explains."""
        used = self.w > 0
        return float(np.sum(self.x[used] ** 2 / self.w[used]))


@dataclass(frozen=True)
class Kernels:
    """How a slope smears the model (weights per phase bin, see ``analysis.sampling.rows``): over the
    sphere's rows (rows), and over the frames' shifts weighted as the timing weighs them, by v^2
    (shifts)."""

    rows: np.ndarray
    shifts: np.ndarray


def point_kernels(bins: int = PHASE_BINS) -> Kernels:
    """A point sphere on one row: no smearing."""
    delta = np.zeros(bins)
    delta[0] = 1.0
    return Kernels(delta, delta)


def kernels(residuals: TimingResiduals, rate: float, rows: SphereRows, slope: float, bins: int = PHASE_BINS) -> Kernels:
    """The kernels of ``slope`` (s per row) at ``rate``."""
    radius = rate * abs(slope) * rows.radius_px
    return Kernels(disc_kernel(radius, bins), shift_kernel(rate * rows.shifts(slope), residuals.v**2, bins))


def bias_table(rate: float, exposures_s: np.ndarray, bins: int = PHASE_BINS, smear: Kernels | None = None) -> np.ndarray:
    """The bias (s) of ``rate`` per exposure and phase bin, smeared by the kernels of a slope (none by default)."""
    smear = point_kernels(bins) if smear is None else smear
    centres = (np.arange(bins) + 0.5) / bins
    g = exposure_bias(centres[None, :], exposures_s[:, None] * rate)
    return smeared(smeared(g, smear.rows), smear.shifts) / rate


@dataclass(frozen=True)
class Fit:
    """One rate's timing misfits over (slopes, exposures, phases) and each hypothesis's weighted mean
    bias (s); the slopes (s per row) and the frames folded."""

    rate: float
    slopes: np.ndarray
    folding: Folding
    timing: np.ndarray
    mean: np.ndarray


def fit_one(residuals: TimingResiduals, table: np.ndarray, folding: Folding) -> tuple[np.ndarray, np.ndarray]:
    """(misfit, mean bias) of the bias ``table`` (exposures, bins) for every exposure and phase
    j / bins, the frames folded by ``folding``: each phase a circular shift of the per-bin model,
    so a few FFTs."""
    bins = table.shape[1]

    def correlate(values: np.ndarray, table: np.ndarray) -> np.ndarray:
        return np.fft.irfft(np.conj(np.fft.rfft(values))[None, :] * np.fft.rfft(table, axis=1), bins, axis=1)

    total_w, total_x = folding.w.sum(), folding.x.sum()
    mean = correlate(folding.w, table) / max(total_w, 1e-300)
    squares = float(residuals.r @ residuals.r)
    misfit = squares + 2 * correlate(folding.x, table) - 2 * mean * total_x + correlate(folding.w, table**2) - mean**2 * total_w
    return misfit, mean


def fit(
    residuals: TimingResiduals, rate: float, exposures_s: np.ndarray, rows: SphereRows | None, slopes: np.ndarray | None = None
) -> Fit:
    """The misfits of ``rate`` over the row ``slopes`` (by default the coarse grid the sphere's rows
    allow; one, 0, without them), every exposure and every phase."""
    if slopes is None:
        slopes = rows.slopes(rate) if rows is not None else np.zeros(1)
    folding = Folding(residuals, rate, PHASE_BINS, rows.frame_times(residuals.t) if rows is not None else None)
    misfits, means = [], []
    for slope in slopes:
        smear = kernels(residuals, rate, rows, float(slope)) if rows is not None else None
        misfit, mean = fit_one(residuals, bias_table(rate, exposures_s, PHASE_BINS, smear), folding)
        misfits.append(misfit)
        means.append(mean)
    return Fit(rate, slopes, folding, np.stack(misfits), np.stack(means))


def frame_biases(residuals: TimingResiduals, fitted: Fit, rows: SphereRows | None, at: tuple[int, int, int], exposure_s: float) -> np.ndarray:
    """Per frame, the bias (s) of the hypothesis ``at`` = (slope, exposure, phase) indices of
    ``fitted``, at ``exposure_s``: its phase bin's."""
    slope_index, _, phase_index = at
    smear = kernels(residuals, fitted.rate, rows, float(fitted.slopes[slope_index])) if rows is not None else None
    table = bias_table(fitted.rate, np.array([exposure_s]), PHASE_BINS, smear)
    return table[0][(fitted.folding.index + phase_index) % PHASE_BINS]
