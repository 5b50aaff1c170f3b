"""Pictures of an analysis for people: tracks and fits with a zoom on one swing's zero crossing where
the lag itself shows, residuals, latency over time, the posterior. Every legend sits above its
panel, never on the data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from analysis.result import LatencyResult
from analysis.signals import SwingSignals, swing_signals

# The top panels show at most this many seconds from the start of the clip, so swings stay visible.
SHOWN_SECONDS = 4.0
ZOOM_LAGS = 6.0
"""The zoom on the lag spans this many lags either side of the LED's zero crossing..."""
ZOOM_FRAMES = 2.0
"""...and at least this many frame intervals."""
LINE_FRAMES = 10
"""Each signal's straight line through its zero crossing is fitted to this many frames either side:
several refreshes of a display that holds each image, so the line follows the swing, not the steps."""


def _delayed_led_residual(result: LatencyResult) -> tuple[np.ndarray, np.ndarray]:
    """(t, sphere minus the LED delayed by the latency and scaled to the sphere): what no fit explains."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t, led, sphere = signals.uniform()
    delayed = np.interp(t - result.latency_ms / 1e3, t, led)
    scale = float(delayed @ sphere / max(delayed @ delayed, 1e-12))
    return t, sphere - scale * delayed


def _legend_above(axes: Axes, columns: int = 3) -> None:
    """The axes' legend in a row above it, clear of the data."""
    axes.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncols=columns, fontsize=8, borderaxespad=0.0, frameon=False)


def _line_zero(dt: np.ndarray, values: np.ndarray) -> tuple[float, float] | None:
    """(slope, time of its zero) of the straight line fitted to the finite (dt, values)."""
    finite = np.isfinite(values)
    if np.count_nonzero(finite) < 3:
        return None
    slope, intercept = np.polyfit(dt[finite], values[finite], 1)
    return (float(slope), -float(intercept) / float(slope)) if slope > 0.0 else None


def _around_rising_zeros(t: np.ndarray, led: np.ndarray, sphere: np.ndarray, half_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every sample within `half_s` of one of the LED's upward zero crossings, pooled over the film:
    (time from that crossing, LED, sphere)."""
    rising = np.flatnonzero((led[:-1] < 0.0) & (led[1:] >= 0.0))
    pooled: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for i in rising:
        zero = t[i] - led[i] * (t[i + 1] - t[i]) / (led[i + 1] - led[i])
        near = np.abs(t - zero) <= half_s
        pooled.append((t[near] - zero, led[near], sphere[near]))
    if not pooled:
        return np.empty(0), np.empty(0), np.empty(0)
    dt, led_near, sphere_near = (np.concatenate(parts) for parts in zip(*pooled))
    return dt, led_near, sphere_near


def _plot_lag(axes: Axes, result: LatencyResult, signals: SwingSignals) -> None:
    """Both signals, normalised, around the LED's upward zero crossings (where the swing moves
    fastest), every swing's samples pooled on the time from its crossing: the LED's straight line
    through them, and that line delayed by the measured latency, which the sphere's samples follow.
    A lag of a millisecond is a fraction of a pixel over the whole swing, and plain to see here."""
    t, led, sphere = signals.uniform()
    led, sphere = led / np.nanmax(np.abs(led)), sphere / np.nanmax(np.abs(sphere))
    axes.set_xlabel("time from the LED's upward zero crossing (ms)")
    axes.set_ylabel("swing (normalised)")
    step = signals.frame_interval
    dt, led_near, sphere_near = _around_rising_zeros(t, led, sphere, LINE_FRAMES * step)
    line = _line_zero(dt, led_near) if dt.size else None
    if line is None:
        axes.set_title("no upward zero crossing of the LED's swing to zoom on", fontsize=9)
        return
    slope, zero = line
    lag_s = result.latency_ms / 1e3
    half = max(ZOOM_LAGS * abs(lag_s), ZOOM_FRAMES * step)
    span = np.array([-half, half]) + zero + lag_s / 2
    shown = np.abs(dt - zero - lag_s / 2) <= half
    axes.plot(dt[shown] * 1e3, led_near[shown], ".", color="C0", markersize=3, alpha=0.5, label="LED, every swing")
    axes.plot(dt[shown] * 1e3, sphere_near[shown], ".", color="C1", markersize=3, alpha=0.6, label="sphere, every swing")
    axes.plot(span * 1e3, slope * (span - zero), "-", color="C0", linewidth=1.5, label="LED's line")
    axes.plot(span * 1e3, slope * (span - zero - lag_s), "--", color="C1", linewidth=1.5, label=f"delayed {result.latency_ms:.2f} ms")
    axes.axhline(0.0, color="grey", linewidth=0.6)
    axes.annotate("", xy=((zero + lag_s) * 1e3, 0.0), xytext=(zero * 1e3, 0.0),
                  arrowprops={"arrowstyle": "<->", "color": "C3", "shrinkA": 0, "shrinkB": 0})  # fmt: skip
    axes.set_title(f"zoom: the sphere lags the LED by {result.latency_ms:.2f} ms", fontsize=9, pad=30)
    axes.set_xlim(*(span * 1e3))
    _legend_above(axes, columns=2)


def tracks_plot(result: LatencyResult, title: str | None = None) -> Figure:
    """The analysis as one figure: both swing signals with the fitted model (sinefit, when run) and
    beside them the zoom on the lag, the residuals, the latency per swing with every method's
    estimate and interval, and the bayes posterior when it was sampled."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t = signals.t
    shown = t <= t[0] + SHOWN_SECONDS
    fit = result.methods["sinefit"].fit if "sinefit" in result.methods else None
    bayes = result.methods.get("bayes")

    figure = Figure(figsize=(13, 11), layout="constrained")
    panels = figure.subplot_mosaic([["tracks", "lag"], ["residuals", "residuals"], ["over_time", "over_time"], ["last", "last"]],
                                   width_ratios=(3, 1))  # fmt: skip
    tracks, residuals, over_time, last = (panels[name] for name in ("tracks", "residuals", "over_time", "last"))
    _plot_lag(panels["lag"], result, signals)
    tracks.plot(t[shown], signals.led[shown], ".", markersize=2, label="LED (real)")
    tracks.plot(t[shown], signals.sphere[shown], ".", markersize=2, label="sphere (rendered)")
    curves = fit.curves() if fit is not None else None
    if curves is not None:
        for index, (times, _, fitted) in enumerate(curves):
            keep = times <= t[0] + SHOWN_SECONDS
            tracks.plot(times[keep], fitted[keep], "k-", linewidth=0.8, label=f"fit ({fit.model})" if index == 0 else None)
    tracks.set_ylabel("swing along its axis (px)")
    tracks.set_xlabel("time in video (s)")
    _legend_above(tracks)

    if curves is not None:
        for name, (times, values, fitted) in zip(("LED", "sphere"), curves, strict=True):
            residuals.plot(times, values - fitted, ".", markersize=3, label=f"{name} - fit")
        residuals.set_title(f"residuals of the fit, {fit.problem.bins.frames_per_bin} frame(s) per point", fontsize=9, pad=22)
    else:
        rt, residual = _delayed_led_residual(result)
        residuals.plot(rt, residual, ".", markersize=2, label="sphere - delayed, scaled LED")
    residuals.set_ylabel("residual (px)")
    residuals.set_xlabel("time in video (s)")
    _legend_above(residuals)

    windowed = result.windowed
    if windowed is not None:
        over_time.plot(windowed.t, windowed.latency_s * 1e3, "o-", color="grey", markersize=3, label=(
            f"per swing: mean {windowed.mean_s * 1e3:.2f} ms, sd {windowed.sd_s * 1e3:.2f} ms"
        ))  # fmt: skip
    for index, (name, estimate) in enumerate(result.methods.items()):
        colour = f"C{index + 2}"
        over_time.axhline(estimate.latency_ms, color=colour, linewidth=1, label=f"{name}: {estimate.latency_ms:.2f} ms")
        if estimate.ci95_ms is not None:
            over_time.axhspan(*estimate.ci95_ms, color=colour, alpha=0.15)
    over_time.set_ylabel("latency (ms)")
    over_time.set_xlabel("time in video (s)")
    _legend_above(over_time, columns=4)

    if bayes is not None:
        samples = bayes.fit.samples_s * 1e3
        last.hist(samples, bins=60, color="C5", alpha=0.7)
        for bound in bayes.ci95_ms:
            last.axvline(bound, color="k", linestyle="--", linewidth=1)
        last.axvline(bayes.latency_ms, color="k", linewidth=1)
        last.set_xlabel("latency (ms)")
        last.set_ylabel("posterior samples")
        last.set_title(
            f"bayes posterior: median {bayes.latency_ms:.3f} ms, 95% {bayes.ci95_ms[0]:.3f} to {bayes.ci95_ms[1]:.3f} ms",
            fontsize=9,
        )
    else:
        delay = result.latency_ms / 1e3
        led_norm = signals.led / np.nanmax(np.abs(signals.led))
        sphere_norm = signals.sphere / np.nanmax(np.abs(signals.sphere))
        last.plot(t[shown] + delay, led_norm[shown], ".", markersize=2, label=f"LED delayed by {result.latency_ms:.2f} ms")
        last.plot(t[shown], sphere_norm[shown], ".", markersize=2, label="sphere")
        last.set_xlabel("time in video (s)")
        last.set_ylabel("swing (normalised)")
        _legend_above(last)

    flag = ", AMBIGUOUS" if result.ambiguous else ""
    figure.suptitle(title or f"latency {result.latency_ms:.2f} ms ({result.method}, {result.model}{flag})")
    return figure


def plot_tracks(result: LatencyResult, path: str | Path, title: str | None = None) -> Path:
    """Write `tracks_plot` as a PNG."""
    path = Path(path)
    tracks_plot(result, title).savefig(path, dpi=100)
    return path
