"""The bands a flashing light draws, fitted over all rows of all frames at once.

Row y of frame k records its dark level plus its own gain times ``on_fraction(u, e, duty)``, with
u = f' (t_k + y L) - psi (``analysis.shutter.model``): f' = f + nu is the flash frequency as the
film's clock sees it (the given one, off by a little: a display's 59.94 Hz against the 60 Hz it
is called), L the time between rows (s per row; 0 for a global shutter), e the exposure in
cycles. Every frame and row is fitted together, so L is found from the bands' spatial period
where they repeat across the rows, and from how they move from frame to frame at the frames'
times where they do not (a slow flash, a short readout, a display whose scan-out nearly follows
the camera's); a global shutter's frames go light and dark whole, and L comes out 0 within its
uncertainty.

The start is the strongest peak of the film's two-dimensional Fourier transform at the flash
frequency (rows against frame times: its row frequency is f' L, its phase psi); a few peaks are
tried. Each row's dark level and gain are solved exactly for every trial of the other five
parameters (variable projection), so uneven lighting costs nothing. The uncertainties come from a
jackknife over blocks of frames: the spread of the fit when each block is left out in turn.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace

import numpy as np
from analysis.shutter.film import RowFilm
from analysis.shutter.model import on_fraction, on_fraction_derivatives

# The flash frequency seen may differ from the given one by this share, and by at most this share
# of its distance to the nearest multiple of half the frame rate: frames taken 1 / fps apart see
# f and k fps - f alike (with the rows' order reversed), so the given frequency must decide.
NU_SHARE = 0.01
NU_ALIAS_SHARE = 0.5
CANDIDATE_PEAKS = 3
JACKKNIFE_BLOCKS = 10
# Student's t at 97.5 % for JACKKNIFE_BLOCKS - 1 degrees of freedom: the 95 % half-width factor.
T95 = 2.262
# A row sample is on a ramp while its on-fraction is strictly between these.
RAMP = (0.02, 0.98)
MIN_RAMP_ROWS = 3
# The fit's parameters (see _Data.to_x) stay within these: the duty in cycles, the exposure as a
# share of the shorter of the on and off times (so the ramps never meet in a fit, and of the four
# readings of the bands, ``analysis.shutter.model.other_readings``, the fit holds the one whose
# ramps are the exposure).
DUTY_BOUNDS = (0.01, 0.99)
EXPOSURE_BOUNDS = (1e-4, 0.999)
MAX_ITERATIONS = 100
# The flash frequency's profile: held this many steps across its whole range, a fit whose cost is
# within this many residual variances of the best explains the film as well.
PROFILE_STEPS = 16
PROFILE_CHI2 = 10.0
# Exposures a fit may start from, as shares of the shorter of the light's on and off times, and
# row frequencies, in steps of the Fourier grid's about each peak's.
EXPOSURE_STARTS = np.array([0.03, 0.1, 0.2, 0.35, 0.5, 0.7])
ROW_OFFSETS = (-1.0, -0.5, 0.0, 0.5, 1.0)


@dataclass(frozen=True)
class Bands:
    """The fitted parameters: line_s (L, s per row, signed), nu_hz (f' - f), phase (psi, cycles),
    duty, exposure (e, cycles of the flash)."""

    line_s: float
    nu_hz: float
    phase: float
    duty: float
    exposure: float


@dataclass(frozen=True)
class BandFit:
    """The fit (``bands``), the flash frequency seen (``flash_hz``), each quantity's jackknife
    standard error (``sd``: line_s, exposure_s, duty, flash_hz), how well the model explains the
    rows (``misfit``: the residual's RMS over the rows' swing), the largest gap between the phases
    the frames caught the flash at (cycles, at the middle row), how many frames caught the light switching in at least
    MIN_RAMP_ROWS rows, and the frames' times against the bands' (``timing_rms_s``: the robust RMS
    of the shift that best fits each such frame alone). ``spread`` is how far the line time and the
    exposure can move (each way, s) while the flash frequency seen moves within its range and the
    fit stays as good (see ``_frequency_profile``): 0 where the film pins the frequency."""

    bands: Bands
    flash_hz: float
    sd: dict[str, float]
    spread: dict[str, float]
    misfit: float
    phase_gap: float
    ramp_frames: int
    timing_rms_s: float


class _Data:
    """A film's samples in the fit's units: times and rows centred, weights by pixels averaged."""

    def __init__(self, film: RowFilm, frames: np.ndarray, flash_hz: float) -> None:
        self.flash_hz = flash_hz
        self.levels = film.levels[frames]
        self.t = film.times[frames] - film.times.mean()
        self.y = film.rows - film.rows.mean()
        self.weights = np.sqrt(film.pixels / film.pixels.mean())
        self.span_rows = float(np.ptp(film.rows)) + 1.0
        self.span_s = float(np.ptp(film.times)) + film.frame_interval_s
        half_fps = 0.5 / film.frame_interval_s
        self.nu_max = min(NU_SHARE * flash_hz, NU_ALIAS_SHARE * abs(flash_hz - half_fps * round(flash_hz / half_fps)))
        reach = self.nu_max * self.span_s
        self.lower = np.array([-np.inf, -reach, -np.inf, DUTY_BOUNDS[0], EXPOSURE_BOUNDS[0]])
        self.upper = np.array([np.inf, reach, np.inf, DUTY_BOUNDS[1], EXPOSURE_BOUNDS[1]])

    def holding_nu(self, nu_hz: float) -> _Data:
        """The same samples, the flash frequency seen held at the given one plus ``nu_hz``."""
        held = copy.copy(self)
        held.lower, held.upper = self.lower.copy(), self.upper.copy()
        held.lower[1] = held.upper[1] = nu_hz * self.span_s
        return held

    def to_x(self, bands: Bands) -> np.ndarray:
        """Parameters of order one: band cycles across the rows, cycles gained over the film, psi,
        duty, and e over the shorter of the duty and its complement."""
        f = self.flash_hz + bands.nu_hz
        shorter = min(bands.duty, 1.0 - bands.duty)
        return np.array([f * bands.line_s * self.span_rows, bands.nu_hz * self.span_s, bands.phase, bands.duty, bands.exposure / shorter])

    def bands(self, x: np.ndarray) -> Bands:
        nu = x[1] / self.span_s
        return Bands(x[0] / self.span_rows / (self.flash_hz + nu), nu, x[2], x[3], x[4] * min(x[3], 1.0 - x[3]))

    def phases(self, bands: Bands, shifts: np.ndarray | float = 0.0) -> np.ndarray:
        """Where each sample's exposure starts, in cycles of the flash (frames, rows); ``shifts``
        (cycles, one per frame) move frames against their times."""
        f = self.flash_hz + bands.nu_hz
        return f * self.t[:, None] + np.reshape(shifts, (-1, 1)) + f * bands.line_s * self.y[None, :] - bands.phase

    def model(self, bands: Bands) -> np.ndarray:
        """Each sample's on-fraction, (frames, rows)."""
        return on_fraction(self.phases(bands), bands.exposure, bands.duty)

    def rows_fit(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each row's dark level and gain that best explain its levels by ``g`` (least squares)."""
        centred = g - g.mean(axis=0)
        spread = (centred**2).mean(axis=0)
        gain = (centred * (self.levels - self.levels.mean(axis=0))).mean(axis=0) / np.maximum(spread, 1e-12)
        return self.levels.mean(axis=0) - gain * g.mean(axis=0), gain

    def residuals(self, x: np.ndarray, jacobian: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
        """The weighted residuals, (frames, rows), and, if asked, their Jacobian in x, (5, frames,
        rows): Kaufman's for variable projection, each derivative of the model with the part each
        row's dark level and gain take up projected out."""
        bands = self.bands(x)
        u = self.phases(bands)
        g = on_fraction(u, bands.exposure, bands.duty)
        dark, gain = self.rows_fit(g)
        residuals = (self.levels - dark - gain * g) * self.weights
        if not jacobian:
            return residuals, None
        slopes = on_fraction_derivatives(u, bands.exposure, bands.duty, g)
        by_u = slopes[0]
        shorter, side = (bands.duty, 1.0) if bands.duty <= 0.5 else (1.0 - bands.duty, -1.0)
        by_duty = slopes[2] + slopes[1] * x[4] * side  # the exposure moves with the shorter plateau
        derivatives = np.stack([by_u * self.y / self.span_rows, by_u * self.t[:, None] / self.span_s, -by_u, by_duty, slopes[1] * shorter])
        derivatives *= -(gain * self.weights)
        derivatives -= derivatives.mean(axis=1, keepdims=True)
        centred = g - g.mean(axis=0)
        along = (derivatives * centred).sum(axis=1, keepdims=True) / np.maximum((centred**2).sum(axis=0), 1e-12)
        return residuals, derivatives - along * centred


def fit_bands(film: RowFilm, flash_hz: float, line_max_s: float) -> BandFit:
    """Fit the film's bands (see the module); ``line_max_s`` is the largest |L| to look for."""
    data = _Data(film, np.arange(len(film.times)), flash_hz)
    fits = [_refine(data, start) for start in _starts(data, line_max_s)]
    best = min(fits, key=lambda pair: pair[1])[0]
    best = _positive_gain(data, best)
    spread = _frequency_profile(data, best)
    replicates = [_refine(_Data(film, keep, flash_hz), best)[0] for keep in _leave_one_block_out(len(film.times))]
    g = data.model(best)
    dark, gain = data.rows_fit(g)
    misfit = float(np.sqrt(np.mean(((data.levels - dark - gain * g) / np.maximum(np.abs(gain), 1e-12)) ** 2)))
    on_ramp = (g > RAMP[0]) & (g < RAMP[1])
    informative = on_ramp.sum(axis=1) >= MIN_RAMP_ROWS
    return BandFit(
        bands=best,
        flash_hz=flash_hz + best.nu_hz,
        sd=_jackknife_sd(best, replicates, flash_hz),
        spread=spread,
        misfit=misfit,
        phase_gap=largest_gap((flash_hz + best.nu_hz) * data.t - best.phase),
        ramp_frames=int(informative.sum()),
        timing_rms_s=_timing_rms(data, best, dark, gain, informative),
    )


def _starts(data: _Data, line_max_s: float) -> list[Bands]:
    """Starting points from the strongest peaks of the film's Fourier transform near the flash
    frequency: row frequency (cycles per row) against the frame times' frequency. Each peak's row
    frequency is known only to a fraction of a cycle across the rows (a display's bands span less
    than one), so a peak's starts are the best of several exposures at its own row frequency and the
    best at the row frequencies about it."""
    low, high = np.percentile(data.levels, [5, 95], axis=0)
    shares = (data.levels - low) / np.maximum(high - low, 1e-9)
    centred = shares - shares.mean(axis=0)
    f = data.flash_hz
    row_max = min(1.25 * f * line_max_s, 0.5 / max(float(np.min(np.diff(data.y))), 1.0)) if len(data.y) > 1 else 0.0
    row_step = 0.2 / data.span_rows
    row_freqs = _symmetric_grid(row_max, row_step)
    nus = _symmetric_grid(data.nu_max, 0.2 / data.span_s)
    by_time = np.exp(-2j * np.pi * (f + nus)[:, None] * data.t[None, :]) @ centred
    spectrum = by_time @ np.exp(-2j * np.pi * data.y[:, None] * row_freqs[None, :])
    power = np.abs(spectrum)
    duty = float(np.clip(shares.mean(), 0.05, 0.95))
    starts = []
    for _ in range(CANDIDATE_PEAKS):
        i, j = np.unravel_index(int(np.argmax(power)), power.shape)
        if power[i, j] <= 0:
            break
        nu, peak = float(nus[i]), spectrum[i, j]
        phases = {exposure: float((np.pi * (exposure - duty) - np.angle(peak)) / (2 * np.pi)) for exposure in EXPOSURE_STARTS * min(duty, 1.0 - duty)}
        trials = {
            offset: [Bands((row_freqs[j] + offset * row_step) / (f + nu), nu, phase, duty, exposure) for exposure, phase in phases.items()]
            for offset in ROW_OFFSETS
        }
        costs = {offset: [float(np.sum(data.residuals(data.to_x(bands))[0] ** 2)) for bands in row] for offset, row in trials.items()}
        best = min(costs, key=lambda offset: min(costs[offset]))
        starts += [trials[offset][int(np.argmin(costs[offset]))] for offset in dict.fromkeys((best, 0.0))]
        power[max(0, i - 2) : i + 3, max(0, j - 2) : j + 3] = 0.0
    return starts


def _symmetric_grid(largest: float, step: float) -> np.ndarray:
    """Multiples of ``step`` from -``largest`` to ``largest``, zero among them."""
    count = int(np.floor(largest / step))
    return np.arange(-count, count + 1) * step


def _refine(data: _Data, start: Bands) -> tuple[Bands, float]:
    """Levenberg-Marquardt from ``start`` within the parameters' bounds (a parameter whose bounds
    meet is held); the bands and the cost."""
    x = np.clip(data.to_x(start), data.lower, data.upper)
    residuals, jacobian = data.residuals(x, jacobian=True)
    cost = float(np.sum(residuals**2))
    damping = 1e-3
    free = data.upper > data.lower
    for _ in range(MAX_ITERATIONS):
        assert jacobian is not None
        flat = jacobian.reshape(len(x), -1)[free]
        normal = flat @ flat.T
        gradient = flat @ residuals.ravel()
        while damping < 1e10:
            step = np.zeros_like(x)
            step[free] = np.linalg.solve(normal + damping * np.diag(np.diag(normal) + 1e-12), -gradient)
            trial = np.clip(x + step, data.lower, data.upper)
            trial_residuals, _ = data.residuals(trial)
            trial_cost = float(np.sum(trial_residuals**2))
            if trial_cost < cost:
                break
            damping *= 4.0
        else:
            break
        converged = cost - trial_cost <= 1e-10 * cost
        x, cost, damping = trial, trial_cost, max(damping / 3.0, 1e-9)
        if converged:
            break
        residuals, jacobian = data.residuals(x, jacobian=True)
    return data.bands(x), cost


def _positive_gain(data: _Data, bands: Bands) -> Bands:
    """The same fit read with the light on where the rows are bright: a fit whose rows mostly
    brighten as the modelled light goes off is the complement's (duty 1 - d, on from psi + d)."""
    _, gain = data.rows_fit(data.model(bands))
    if np.median(gain) >= 0:
        return bands
    return _refine(data, replace(bands, phase=bands.phase + bands.duty, duty=1.0 - bands.duty))[0]


def _frequency_profile(data: _Data, best: Bands) -> dict[str, float]:
    """How far the line time and the exposure move (the largest change either way, s) along fits
    that explain the film as well as the best (cost within PROFILE_CHI2 residual variances) with the
    flash frequency held further and further from the best's, PROFILE_STEPS steps across its range
    each way, each fit starting from the last. A flash that only drifts slowly against a simple
    fraction of the frame rate shows the same film for a range of frequencies, each with its own
    line time and exposure; a film that pins the frequency leaves 0."""
    x = data.to_x(best)
    residuals, _ = data.residuals(x)
    cost = float(np.sum(residuals**2))
    limit = cost + PROFILE_CHI2 * cost / max(residuals.size - len(x), 1)
    exposure = best.exposure / (data.flash_hz + best.nu_hz)
    spread = {"line_s": 0.0, "exposure_s": 0.0}
    for direction in (-1.0, 1.0):
        bands = best
        for step in range(1, PROFILE_STEPS + 1):
            nu = best.nu_hz + direction * step * data.nu_max / PROFILE_STEPS * 2.0
            if abs(nu) > data.nu_max:
                break
            bands, trial = _refine(data.holding_nu(nu), replace(bands, nu_hz=nu))
            if trial > limit:
                break
            spread["line_s"] = max(spread["line_s"], abs(bands.line_s - best.line_s))
            spread["exposure_s"] = max(spread["exposure_s"], abs(bands.exposure / (data.flash_hz + nu) - exposure))
    return spread


def _leave_one_block_out(count: int) -> list[np.ndarray]:
    blocks = np.array_split(np.arange(count), JACKKNIFE_BLOCKS)
    return [np.concatenate([block for j, block in enumerate(blocks) if j != i]) for i in range(len(blocks))]


def _jackknife_sd(best: Bands, replicates: list[Bands], flash_hz: float) -> dict[str, float]:
    def derived(bands: Bands) -> dict[str, float]:
        f = flash_hz + bands.nu_hz
        return {"line_s": bands.line_s, "exposure_s": bands.exposure / f, "duty": bands.duty, "flash_hz": f}

    values = [derived(bands) for bands in replicates]
    n = len(values)
    return {key: float(np.sqrt((n - 1) / n * np.sum((np.array([v[key] for v in values]) - np.mean([v[key] for v in values])) ** 2))) for key in derived(best)}


def largest_gap(phases: np.ndarray) -> float:
    """The largest gap (cycles) between phases taken modulo one cycle."""
    ordered = np.sort(np.mod(phases, 1.0))
    return float(np.max(np.diff(np.concatenate([ordered, [ordered[0] + 1.0]]))))


def _timing_rms(data: _Data, bands: Bands, dark: np.ndarray, gain: np.ndarray, informative: np.ndarray) -> float:
    """The robust RMS (s) of the time shift that best fits each informative frame alone: searched
    over a quarter period either way, then around each frame's best to a 64th of that step."""
    if not informative.any():
        return float("nan")

    def best(shifts: np.ndarray) -> np.ndarray:  # shifts (trials, frames) in cycles: each frame's best
        costs = [
            (((data.levels - dark - gain * on_fraction(data.phases(bands, trial), bands.exposure, bands.duty)) * data.weights) ** 2).sum(axis=1)
            for trial in shifts
        ]
        return shifts[np.argmin(costs, axis=0), np.arange(shifts.shape[1])]

    frames = len(data.t)
    coarse = best(np.repeat(np.linspace(-0.25, 0.25, 41)[:, None], frames, axis=1))
    fine = best(coarse[None, :] + np.linspace(-0.0125, 0.0125, 41)[:, None])
    return float(1.4826 * np.median(np.abs(fine[informative]))) / (data.flash_hz + bands.nu_hz)
