"""A camera's readout and exposure from a film of a flashing light, or the reason the film cannot tell.

The bands are fitted (``analysis.shutter.fit``); then what the fit found is read as a camera:

- A display flashing full-field (``ShutterOptions.source``) scans its rows out too, so the bands
  move at the difference of the camera's and the display's row rates: the display's time per
  camera row (its scan-out time over the panel's height in the film, signed by its direction) is
  added back. The scan-out time is the refresh period's share the lab gives, or 88 to 100 % of it
  (the range of common video timings' vertical blanking), in the interval either way.
- The readout's interval is the jackknife's 95 % (Student's t) with the display's terms beside,
  plus the line times of the equally good fits at other flash frequencies the film allows; where
  it holds 0 the camera has a global shutter, and the answer is readout 0 with the interval's top
  as its bound.
- The exposure is the ramps' length, but a film cannot tell it from three other readings of the
  same trapezoid (``analysis.shutter.model.other_readings``). Each is ruled out by the light's duty
  cycle, when given, or by the longest exposure the camera can have (the frame interval, or the
  lab's own bound); one that is not makes the film undecided.

Every refusal is an AnalysisError in one line naming what to change.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

import numpy as np

from analysis.caveat import caveat
from analysis.errors import AnalysisError
from analysis.shutter.film import RowFilm, read_film
from analysis.shutter.fit import T95, BandFit, fit_bands, largest_gap
from analysis.shutter.model import LONGER_THAN_BOTH, Reading, other_readings
from analysis.shutter.options import ShutterOptions
from analysis.shutter.result import ShutterResult

MIN_FRAMES = 40
# Before fitting: the frames must catch the flash at phases no further apart than this (cycles).
MAX_PHASE_GAP = 0.3
# After: no further apart than this share of the shorter plateau, so every row is seen on and off.
PLATEAU_COVER = 0.8
MIN_RAMP_FRAMES = 10
# A suggested flash is caught by this many frames at phases no more than this far apart (cycles).
SUGGESTED_FRAMES = 60
SUGGESTED_GAP = 0.06
MAX_MISFIT = 0.15
# The ramps meet when the exposure reaches this share of the shorter of the on and off times.
RAMPS_MEET = 0.85
DUTY_TOLERANCE = 0.03
# An exposure this much over the longest the camera can take is still possible (timing rounding).
EXPOSURE_SLACK = 1.02
# A rolling shutter's readout or an exposure known no better than this share (95 %), or a global
# shutter's bound above this share of the frame interval, is not an answer.
MAX_SPREAD = 0.25
# Without the display's scan-out share, it is taken to lie in this range.
SCANOUT_SHARES = (0.88, 1.0)
# A display panel's height in the film is known to this many rows (95 %): its edges are placed to
# a fraction of a row (``analysis.shutter.film``), which the panel's own light at its border blurs.
PANEL_EDGE_ROWS = 0.5
# The frames' times disagree with the bands when each frame's best shift spreads by more than this
# share of the exposure; the exposure's interval then reaches down by this many times that spread.
TIMING_SHARE = 0.1
TIMING_WIDENING = 2.0
# No interval is narrower than these shares, nor than SWITCHING_S either way: what the model
# leaves out (rows not read at exactly equal intervals, a light that does not switch instantly,
# pixels not exactly linear), which the jackknife over frames cannot see.
READOUT_FLOOR = 0.005
EXPOSURE_FLOOR = 0.01
SWITCHING_S = 2e-6


def display_line_s(film: RowFilm, options: ShutterOptions) -> tuple[float, float]:
    """A flashing display's time per camera row, signed as the camera's line time (positive for a
    scan-out that moves down the film), and its 95 % half-width; (0, 0) for a light."""
    if options.source != "display" or options.display_hz is None:
        return 0.0, 0.0
    first, last = film.edges
    x, y, w, h = film.region
    if first < y + 0.5 or last > y + h - 0.5:
        raise AnalysisError(
            "the flashing display reaches the edge of the frame (or of --roi): film the panel's whole height, "
            "its top and bottom edges in view, so that its scan-out can be accounted for"
        )
    rows = last - first
    share = options.scanout_share
    low, high = (share, share) if share is not None else SCANOUT_SHARES
    scan = (low + high) / 2 / options.display_hz
    sign = 1.0 if options.scanout == "top-down" else -1.0
    spread = math.hypot((high - low) / (low + high), PANEL_EDGE_ROWS / rows)
    return sign * scan / rows, scan / rows * spread


def measure_shutter(
    video: str | Path | np.ndarray,
    flash_hz: float,
    options: ShutterOptions = ShutterOptions(),
    progress: Callable[[int, int], object] | None = None,
) -> ShutterResult:
    """The readout and exposure of the camera that filmed ``video`` (a file, a folder of images or
    an (N, H, W) array at ``options.fps``): a light, or a display, flashing at ``flash_hz``, read as
    ``options`` say; ``progress(done, total)`` as frames are read."""
    return estimate_shutter(read_film(video, options.fps, options.roi, progress), flash_hz, options)


def estimate_shutter(film: RowFilm, flash_hz: float, options: ShutterOptions = ShutterOptions()) -> ShutterResult:
    """``measure_shutter`` on a film already reduced to rows (``analysis.shutter.film``)."""
    _check_inputs(film, flash_hz)
    interval = film.frame_interval_s
    display_line, display_spread = display_line_s(film, options)
    line_max = 1.1 * interval / film.height + abs(display_line)
    fit = fit_bands(film, flash_hz, line_max)
    bands = fit.bands
    if fit.misfit > MAX_MISFIT:
        raise AnalysisError(
            f"the rows do not follow a light flashing at {flash_hz:g} Hz (they depart from the best fit by "
            f"{fit.misfit:.0%} of their swing): check --flash-hz, the source, and that nothing else in view changes"
        )
    exposure_s = bands.exposure / fit.flash_hz
    _check_readings(fit, options.duty, options.max_exposure_s if options.max_exposure_s is not None else interval)
    _check_coverage(fit)
    line = bands.line_s + display_line
    causes = {"bands": T95 * fit.sd["line_s"], "display": display_spread, "drift": fit.spread["line_s"]}
    line_half = math.hypot(causes["bands"], causes["display"]) + causes["drift"]
    readout = abs(line) * film.height
    readout_half = max(line_half * film.height, READOUT_FLOOR * readout, SWITCHING_S)
    global_shutter = bool(readout <= readout_half)
    cause = max(causes, key=lambda name: causes[name])
    advice = _advice(cause, flash_hz, interval, exposure_s, bands.duty)
    if global_shutter and readout + readout_half > MAX_SPREAD * interval:
        raise AnalysisError(f"the readout is only known to be below {(readout + readout_half) * 1e3:.2f} ms{advice}")
    if not global_shutter and readout_half > MAX_SPREAD * readout:
        raise AnalysisError(f"the readout is only known to be {readout * 1e3:.2f} +- {readout_half * 1e3:.2f} ms{advice}")
    exposure_half = max(T95 * fit.sd["exposure_s"], EXPOSURE_FLOOR * exposure_s, SWITCHING_S) + fit.spread["exposure_s"]
    if exposure_half > MAX_SPREAD * exposure_s:
        drifting = fit.spread["exposure_s"] > T95 * fit.sd["exposure_s"]
        raise AnalysisError(
            f"the exposure is only known to be {exposure_s * 1e3:.2f} +- {exposure_half * 1e3:.2f} ms"
            f"{_advice('drift' if drifting else 'bands', flash_hz, interval, exposure_s, bands.duty)}"
        )
    # Frames whose times are off blur the ramps, so the exposure may be shorter by about that spread.
    timing_off = fit.timing_rms_s > TIMING_SHARE * exposure_s
    exposure_low = exposure_s - exposure_half - (TIMING_WIDENING * fit.timing_rms_s if timing_off else 0.0)
    band_line = abs(fit.flash_hz * bands.line_s)
    return ShutterResult(
        readout_s=0.0 if global_shutter else readout,
        readout_ci95_s=(0.0, float(readout + readout_half)) if global_shutter else (float(readout - readout_half), float(readout + readout_half)),
        exposure_s=exposure_s,
        exposure_ci95_s=(float(max(exposure_low, 0.0)), float(exposure_s + exposure_half)),
        fps=1.0 / interval,
        line_time_s=0.0 if global_shutter else abs(line),
        global_shutter=global_shutter,
        readout_direction=None if global_shutter else ("top-down" if line > 0 else "bottom-up"),
        source=options.source,
        flash_hz=flash_hz,
        flash_hz_seen=fit.flash_hz,
        duty=bands.duty,
        band_periods=band_line * (float(np.ptp(film.rows)) + 1.0),
        ramp_rows=None if global_shutter else bands.exposure / band_line,
        rows=(int(film.rows[0]), int(film.rows[-1])),
        row_count=len(film.rows),
        frame_height=film.height,
        frames=len(film.times),
        lit_pixels=film.lit,
        saturated_pixels=film.saturated,
        timing_source=film.timing_source,
        timing_rms_s=fit.timing_rms_s,
        misfit=fit.misfit,
        warnings=film.warnings + tuple(_warnings(film, fit, timing_off)),
    )


def _advice(cause: str, flash_hz: float, interval: float, exposure_s: float, duty: float) -> str:
    """What to change where ``cause`` ("bands", "display" or "drift") leaves a figure undecided."""
    if cause == "display":
        return (
            ", most of that from the display's scan-out: give the share of each refresh its scan-out takes, "
            "film the panel taller in the frame, or film a flashing light instead"
        )
    if cause == "drift":
        return (
            f": {flash_hz:g} Hz is so near a simple fraction of the frame rate that the bands only drift, and its "
            "exact frequency and the bands' slope cannot be told apart; film longer, or choose a flash frequency "
            f"whose phase moves on by about a third of a period each frame (such as {_unlocked_flash(flash_hz, interval):.1f} Hz)"
        )
    return f": flash faster (up to {_fastest_flash(exposure_s, duty):.0f} Hz keeps the ramps apart) or let the light fill more rows"


def _check_inputs(film: RowFilm, flash_hz: float) -> None:
    if not (math.isfinite(flash_hz) and flash_hz > 0):
        raise AnalysisError(f"the flash frequency must be a positive number of Hz, not {flash_hz}")
    if len(film.times) < MIN_FRAMES:
        raise AnalysisError(f"the film has only {len(film.times)} frames: film the flashing light for at least {MIN_FRAMES} frames")
    gap = largest_gap(flash_hz * film.times)
    if gap > MAX_PHASE_GAP:
        raise AnalysisError(_standing_bands(flash_hz, film.frame_interval_s, gap))


def _standing_bands(flash_hz: float, interval: float, gap: float) -> str:
    return (
        f"the frames catch the flash at too few phases (gaps of {gap:.2f} of a period): {flash_hz:g} Hz is too near a "
        f"multiple of {0.5 / interval:g} Hz (half the frame rate) or a simple fraction of it; choose a flash frequency "
        f"whose phase moves on by about a third of a period each frame (such as {_unlocked_flash(flash_hz, interval):.1f} Hz)"
    )


def _unlocked_flash(flash_hz: float, interval: float) -> float:
    """A flash frequency near ``flash_hz`` whose phase advances by about 0.38 of a period a frame."""
    fps = 1.0 / interval
    return fps * (math.floor(flash_hz / fps) + 0.382)


def suggest_flash_hz(fps: float, exposure_s: float, duty: float = 0.5, longest_exposure_s: float | None = None) -> float:
    """The fastest flash that films well for a camera at ``fps`` exposing about ``exposure_s``: the
    light's shorter plateau (on or off) at least as long as the exposure, so the ramps stay apart;
    for a duty near 50 %, a period longer than the longest exposure (``longest_exposure_s``, else
    the frame interval) plus the exposure, so an exposure of a period less the measured one is
    ruled out; and a phase that moves on each frame by no simple fraction of a period, so that
    SUGGESTED_FRAMES frames catch the flash at phases no more than SUGGESTED_GAP apart."""
    flash = min(duty, 1.0 - duty) / (2.0 * exposure_s)
    if abs(duty - 0.5) <= DUTY_TOLERANCE:
        longest = longest_exposure_s if longest_exposure_s is not None else 1.0 / fps
        flash = min(flash, 0.95 / (EXPOSURE_SLACK * longest + exposure_s))
    frames = np.arange(SUGGESTED_FRAMES) / fps
    while largest_gap(flash * frames) > SUGGESTED_GAP:
        flash *= 0.99
    return flash


def _check_readings(fit: BandFit, duty: float | None, longest_s: float) -> None:
    """AnalysisError unless the ramps, read as the exposure, are the only reading of the bands
    that the duty cycle given and the longest exposure allow."""
    bands, f = fit.bands, fit.flash_hz
    shorter = min(bands.duty, 1.0 - bands.duty)
    if bands.exposure >= RAMPS_MEET * shorter:
        raise AnalysisError(
            f"the bands' ramps meet: the exposure ({bands.exposure / f * 1e3:.2f} ms or more) fills the light's "
            f"{'on' if bands.duty <= 0.5 else 'off'} time ({shorter / f * 1e3:.2f} ms), so exposure and duty cycle "
            f"cannot be told apart; flash at most {_fastest_flash(bands.exposure / f, bands.duty):.0f} Hz"
        )
    tolerance = DUTY_TOLERANCE + 2.5 * fit.sd["duty"]
    readings = other_readings(bands.exposure, bands.duty)
    if duty is not None and abs(bands.duty - duty) > tolerance:
        longer = [r for r in readings if abs(r.duty - duty) <= tolerance]
        if longer:
            raise AnalysisError(
                f"the bands' ramps meet: with the light on {duty:.0%} of each period, the exposure "
                f"({longer[0].exposure / f * 1e3:.2f} ms) is longer than the light's on or off time; flash at most "
                f"{_fastest_flash(longer[0].exposure / f, duty):.0f} Hz"
            )
        raise AnalysisError(f"the light is on {bands.duty:.0%} of each period, not the {duty:.0%} given: check --duty")
    possible = [
        r for r in readings
        if (duty is None or abs(r.duty - duty) <= tolerance) and r.exposure / f <= EXPOSURE_SLACK * longest_s
    ]  # fmt: skip
    if possible:
        other = possible[0]
        raise AnalysisError(
            f"the film cannot tell an exposure of {bands.exposure / f * 1e3:.2f} ms from one of {other.exposure / f * 1e3:.2f} ms "
            f"({other.which}, the light on {other.duty:.0%} of each period): flash at most "
            f"{min(_alias_free_flash(r, bands.exposure / f, longest_s) for r in possible):.1f} Hz, give the light's duty "
            "cycle (--duty; a duty away from 50 % tells them apart), or give the longest exposure the camera can take"
        )


def _fastest_flash(exposure_s: float, duty: float) -> float:
    """The fastest flash whose shorter plateau is as long as the exposure (ramps well apart)."""
    return min(duty, 1.0 - duty) / (2.0 * exposure_s)


def _alias_free_flash(reading: Reading, exposure_s: float, longest_s: float) -> float:
    """The fastest flash at which ``reading``'s exposure would be longer than ``longest_s``."""
    if reading.which == LONGER_THAN_BOTH:
        return 1.0 / (longest_s + exposure_s)
    return reading.exposure / longest_s


def _check_coverage(fit: BandFit) -> None:
    bands = fit.bands
    plateau = min(bands.duty, 1.0 - bands.duty) - bands.exposure
    if fit.phase_gap > PLATEAU_COVER * plateau:
        raise AnalysisError(
            f"the frames catch the flash at too few phases (gaps of {fit.phase_gap:.2f} of a period, against plateaus of "
            f"{plateau:.2f}) for each row to be seen both on and off: choose a flash frequency whose ratio to the frame "
            "rate is not near a simple fraction, or film longer"
        )
    if fit.ramp_frames < MIN_RAMP_FRAMES:
        raise AnalysisError(
            f"only {fit.ramp_frames} frames caught the light switching: film longer, or choose a flash frequency whose "
            "ratio to the frame rate is not near a simple fraction"
        )


def _warnings(film: RowFilm, fit: BandFit, timing_off: bool) -> list[str]:
    warnings = []
    if timing_off:
        warnings.append(caveat(
            f"the bands shift from frame to frame by {fit.timing_rms_s * 1e3:.3f} ms (RMS) more or less than the frames' "
            f"times ({film.timing_source}) say: the exposure may read long, and its interval allows for that",
            "check that the film keeps the camera's frame times (a recorder that stamps each frame)",
        ))  # fmt: skip
    if film.saturated > film.lit / 2:
        warnings.append(caveat(
            f"{film.saturated} of the {film.lit} pixels the light reaches saturate, and were left out",
            "dim the light or lower the camera's gain",
        ))  # fmt: skip
    return warnings
