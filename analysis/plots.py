"""Pictures of an analysis for people: tracks and fits, residuals, latency over time, the posterior."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from analysis.result import LatencyResult
from analysis.signals import swing_signals

# The top panels show at most this many seconds from the start of the clip, so swings stay visible.
SHOWN_SECONDS = 4.0


def _delayed_led_residual(result: LatencyResult) -> tuple[np.ndarray, np.ndarray]:
    """(t, sphere minus the LED delayed by the latency and scaled to the sphere): what no fit explains."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t, led, sphere = signals.uniform()
    delayed = np.interp(t - result.latency_ms / 1e3, t, led)
    scale = float(delayed @ sphere / max(delayed @ delayed, 1e-12))
    return t, sphere - scale * delayed


def plot_tracks(result: LatencyResult, path: str | Path, title: str | None = None) -> Path:
    """Write a PNG of the analysis: both swing signals with the fitted model (sinefit, when run),
    the residuals, the latency per swing with every method's estimate and interval, and the bayes
    posterior when it was sampled."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t = signals.t
    shown = t <= t[0] + SHOWN_SECONDS
    fit = result.methods["sinefit"].fit if "sinefit" in result.methods else None
    bayes = result.methods.get("bayes")

    figure = Figure(figsize=(10, 10))
    tracks, residuals, over_time, last = figure.subplots(4, 1)
    tracks.plot(t[shown], signals.led[shown], ".", markersize=2, label="LED (real)")
    tracks.plot(t[shown], signals.sphere[shown], ".", markersize=2, label="sphere (rendered)")
    curves = fit.curves() if fit is not None else None
    if curves is not None:
        for index, (times, _, fitted) in enumerate(curves):
            keep = times <= t[0] + SHOWN_SECONDS
            tracks.plot(times[keep], fitted[keep], "k-", linewidth=0.8, label=f"fit ({fit.model})" if index == 0 else None)
    tracks.set_ylabel("swing along its axis (px)")
    tracks.set_xlabel("time in video (s)")
    tracks.legend(loc="upper right", fontsize=8)

    if curves is not None:
        for name, (times, values, fitted) in zip(("LED", "sphere"), curves, strict=True):
            residuals.plot(times, values - fitted, ".", markersize=3, label=f"{name} - fit")
        residuals.set_title(f"residuals of the fit, {fit.problem.bins.frames_per_bin} frame(s) per point", fontsize=9)
    else:
        rt, residual = _delayed_led_residual(result)
        residuals.plot(rt, residual, ".", markersize=2, label="sphere - delayed, scaled LED")
    residuals.set_ylabel("residual (px)")
    residuals.set_xlabel("time in video (s)")
    residuals.legend(loc="upper right", fontsize=8)

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
    over_time.legend(loc="upper right", fontsize=8)

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
        last.legend(loc="upper right", fontsize=8)

    flag = ", AMBIGUOUS" if result.ambiguous else ""
    figure.suptitle(title or f"latency {result.latency_ms:.2f} ms ({result.method}, {result.model}{flag})")
    figure.tight_layout()
    path = Path(path)
    figure.savefig(path, dpi=100)
    return path
