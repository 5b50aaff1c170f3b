"""The misfit of every phase, exposure and row slope of one refresh rate, by folding the frames.

For a refresh rate f, a row slope m (``analysis.sampling.rows``), an exposure e (in refreshes) and a
phase phi, every frame's bias is b_n = G(frac(f (t_n - shift_n) + phi)) / f, G the exposure's bias
g smeared over the sphere's rows by f m and shift_n the time its centroid row moves its phase
(``analysis.sampling.rows``), and the sphere's residuals should read r_n = -v_n (b_n - mean b)
(``analysis.sampling.residuals``); where the sphere's moments were measured, its elongation along
its motion should read c + (v_n / f)^2 S(frac(...)), c its own (fitted) and S the variance of its
image's time: the refreshes each row saw (V, smeared), and the rows' own biases' spread.

Frames are folded by the phase of their dated time, frac(f t_n), into bins: every phi is then a
circular shift, and the misfit over all phases takes a few FFTs per (m, e). A bin's frames are
shifted from it by shift_n, distributed over the frames as the slope's kernel says, so its model is
G smeared once more by that distribution (``analysis.sampling.rows``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.sampling.model import exposure_bias, exposure_spread
from analysis.sampling.residuals import TimingResiduals
from analysis.sampling.rows import SphereRows, disc_kernel, shift_kernel, smeared

PHASE_BINS = 512
# The elongation counts where at least this many frames measured it.
SHAPE_MIN_FRAMES = 32


class Folding:
    """The residuals' sums per phase bin at a refresh rate: W = sum v^2 and X = sum v r for the timing; for the elongation D (frames where it was measured),
    sum v^2, sum v^4, sum D v^2 and its totals."""

    def __init__(self, residuals: TimingResiduals, refresh_hz: float, bins: int, shape: bool = True) -> None:
        phase = refresh_hz * residuals.t
        index = ((phase - np.floor(phase)) * bins).astype(np.int64) % bins
        v2 = residuals.v**2
        self.index = index
        self.w = np.bincount(index, v2, bins)
        self.x = np.bincount(index, residuals.v * residuals.r, bins)
        self.shape: tuple[np.ndarray, np.ndarray, np.ndarray, float, float, int] | None = None
        if shape and residuals.elongation is not None:
            measured = np.isfinite(residuals.elongation)
            if np.count_nonzero(measured) >= SHAPE_MIN_FRAMES:
                where, d, q = index[measured], residuals.elongation[measured], v2[measured]
                sums = (np.bincount(where, q, bins), np.bincount(where, q * q, bins), np.bincount(where, d * q, bins))
                self.shape = (*sums, float(d.sum()), float(d @ d), int(d.size))

    def explained(self) -> float:
        """The sum of squares a free timing offset per bin explains."""
        used = self.w > 0
        return float(np.sum(self.x[used] ** 2 / self.w[used]))


@dataclass(frozen=True)
class Model:
    """A rate's model per exposure and phase bin: the bias (s) and, with the shape, the elongation
    factor S / f^2 (s^2)."""

    rate: float
    bins: int
    bias: np.ndarray
    spread: np.ndarray | None

    def spectra(self) -> tuple[np.ndarray, ...]:
        """The bias and its square, and the elongation factor and its square, as spectra along the
        bins (for circular correlation)."""
        tables = [self.bias, self.bias**2] + ([self.spread, self.spread**2] if self.spread is not None else [])
        return tuple(np.fft.rfft(table, axis=1) for table in tables)


@dataclass(frozen=True)
class Kernels:
    """How a slope smears the model (weights per phase bin, see ``analysis.sampling.rows``): over the
    sphere's rows (rows), and over the frames' shifts weighted as the timing (v^2) and the
    elongation (v^4) weigh them."""

    rows: np.ndarray
    timing: np.ndarray
    shape: np.ndarray


def point_kernels(bins: int = PHASE_BINS) -> Kernels:
    """A point sphere on one row: no smearing."""
    delta = np.zeros(bins)
    delta[0] = 1.0
    return Kernels(delta, delta, delta)


def kernels(residuals: TimingResiduals, rate: float, rows: SphereRows, slope: float, bins: int = PHASE_BINS) -> Kernels:
    """The kernels of ``slope`` (s per row) at ``rate``."""
    shifts = rate * rows.shifts(slope)
    v2 = residuals.v**2
    return Kernels(
        disc_kernel(rate * abs(slope) * rows.radius_px, bins), shift_kernel(shifts, v2, bins), shift_kernel(shifts, v2 * v2, bins)
    )


def model(rate: float, exposures_s: np.ndarray, bins: int = PHASE_BINS, shape: bool = True, smear: Kernels | None = None) -> Model:
    """The tables of ``rate`` for every exposure, smeared by the kernels of a slope (none by default)."""
    smear = point_kernels(bins) if smear is None else smear
    centres = (np.arange(bins) + 0.5) / bins
    exposures = exposures_s[:, None] * rate
    point = exposure_bias(centres[None, :], exposures)
    g = smeared(point, smear.rows)
    spread = None
    if shape:
        rows = smeared(exposure_spread(centres[None, :], exposures), smear.rows) + smeared(point**2, smear.rows) - g**2
        spread = np.maximum(smeared(rows, smear.shape), 0.0) / rate**2
    return Model(rate, bins, smeared(g, smear.timing) / rate, spread)


@dataclass(frozen=True)
class Fit:
    """One rate's misfits over (slopes, exposures, phases): the timing's, the elongation's (None
    where not measured), and each hypothesis's weighted mean bias (s); the slopes (s per row) and
    the frames folded."""

    rate: float
    slopes: np.ndarray
    folding: Folding
    timing: np.ndarray
    shape: np.ndarray | None
    mean: np.ndarray


def fit_one(residuals: TimingResiduals, table: Model, folding: Folding) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """(timing misfit, elongation misfit or None, mean bias) of ``table`` for every exposure and
    phase j / bins, the frames folded by ``folding``: each phase a circular shift of the per-bin
    model, so a few FFTs."""
    spectra = table.spectra()
    bins = table.bins

    def correlate(values: np.ndarray, spectrum: np.ndarray) -> np.ndarray:
        return np.fft.irfft(np.conj(np.fft.rfft(values))[None, :] * spectrum, bins, axis=1)

    bias, bias_square = spectra[:2]
    total_w, total_x = folding.w.sum(), folding.x.sum()
    mean = correlate(folding.w, bias) / max(total_w, 1e-300)
    squares = float(residuals.r @ residuals.r)
    timing = squares + 2 * correlate(folding.x, bias) - 2 * mean * total_x + correlate(folding.w, bias_square) - mean**2 * total_w
    shape_chi2 = None
    if folding.shape is not None and len(spectra) > 2:
        spread, spread_square = spectra[2:]
        q, q2, dq, total_d, total_d2, count = folding.shape
        cross, model_sum = correlate(dq, spread), correlate(q, spread)
        shape_chi2 = total_d2 - 2 * cross + correlate(q2, spread_square) - (total_d - model_sum) ** 2 / count
    return timing, shape_chi2, mean


def fit(
    residuals: TimingResiduals, rate: float, exposures_s: np.ndarray, rows: SphereRows | None, slopes: np.ndarray | None = None
) -> Fit:
    """The misfits of ``rate`` over the row ``slopes`` (by default the coarse grid the sphere's rows
    allow; one, 0, without them), every exposure and every phase."""
    if slopes is None:
        slopes = rows.slopes(rate) if rows is not None else np.zeros(1)
    folding = Folding(residuals, rate, PHASE_BINS)
    with_shape = folding.shape is not None
    timings, shapes, means = [], [], []
    for slope in slopes:
        smear = kernels(residuals, rate, rows, float(slope)) if rows is not None else None
        timing, shape_chi2, mean = fit_one(residuals, model(rate, exposures_s, PHASE_BINS, with_shape, smear), folding)
        timings.append(timing)
        shapes.append(shape_chi2)
        means.append(mean)
    return Fit(rate, slopes, folding, np.stack(timings), np.stack(shapes) if with_shape else None, np.stack(means))


def frame_biases(
    residuals: TimingResiduals, fitted: Fit, rows: SphereRows | None, at: tuple[int, int, int], exposure_s: float
) -> tuple[np.ndarray, np.ndarray | None]:
    """Per frame, the bias (s) and elongation factor (s^2; None without the shape) of the
    hypothesis ``at`` = (slope, exposure, phase) indices of ``fitted``, at ``exposure_s``: its
    phase bin's."""
    slope_index, _, phase_index = at
    smear = kernels(residuals, fitted.rate, rows, float(fitted.slopes[slope_index])) if rows is not None else None
    folding = fitted.folding
    table = model(fitted.rate, np.array([exposure_s]), PHASE_BINS, folding.shape is not None, smear)
    phase = (folding.index + phase_index) % PHASE_BINS
    spread = table.spread[0][phase] if table.spread is not None else None
    return table.bias[0][phase], spread
