"""The pictures of a report, drawn for people to read: every axis labelled with its unit, legends
beside the data rather than on it, the whole film shown (with a zoomed inset where the detail is).
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any, Sequence

import numpy as np
from matplotlib.figure import Figure

from analysis import LatencyResult
from analysis.signals import swing_signals

LEGEND_BESIDE = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "fontsize": 8, "borderaxespad": 0.0}
"""Legend placement: outside the axes, to their right, so it never covers data."""
ZOOM_PERIODS = 2.0
DISTINCT_FREQUENCIES = 0.05
"""Videos whose swing frequencies spread by more than this fraction get a latency-against-frequency panel."""


def _matched(led: np.ndarray, sphere: np.ndarray, delay_s: float, t: np.ndarray) -> np.ndarray:
    """The LED delayed by `delay_s`, scaled and offset (least squares) onto the sphere, at times `t`."""
    delayed = np.interp(t - delay_s, t, led, left=np.nan, right=np.nan)
    both = np.isfinite(delayed) & np.isfinite(sphere)
    design = np.stack([delayed[both], np.ones(np.count_nonzero(both))], axis=1)
    (gain, offset), *_ = np.linalg.lstsq(design, sphere[both], rcond=None)
    return gain * delayed + offset


def tracks_figure(result: LatencyResult) -> Figure:
    """Both swings over the whole film, with the LED delayed by the measured latency and matched to
    the sphere's scale laid on it; below, two swing periods from the middle of the free swing."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t, led, sphere = signals.uniform()
    matched = _matched(led, sphere, result.latency_ms / 1e3, t)
    figure = Figure(figsize=(11, 6.5), layout="constrained")
    whole, zoom = figure.subplots(2, 1, height_ratios=(3, 2))
    start, stop = result.diagnostics.get("swinging_s", (t[0], t[-1]))
    middle = 0.5 * (start + stop)
    half = 0.5 * ZOOM_PERIODS * result.period_s
    close = np.abs(t - middle) <= half
    for axes, keep in ((whole, slice(None)), (zoom, close)):
        axes.plot(t[keep], sphere[keep], ".", markersize=1.5, color="C1", label="sphere (rendered)")
        axes.plot(t[keep], matched[keep], "-", linewidth=0.8, color="C0",
                  label=f"LED delayed by {result.latency_ms:.2f} ms, scaled to the sphere")  # fmt: skip
        axes.set_xlabel("time in video (s)")
        axes.set_ylabel("swing along its axis (px)")
        axes.legend(**LEGEND_BESIDE, markerscale=6)
    whole.axvspan(middle - half, middle + half, color="grey", alpha=0.15, label="zoomed below")
    whole.set_title("the whole film: where the delayed LED lies on the sphere, the latency explains the motion")
    zoom.set_title(f"{ZOOM_PERIODS:g} swing periods from the middle of the free swing")
    return figure


def latency_over_time_figure(result: LatencyResult) -> Figure:
    """The latency swing by swing over the film, beside every method's estimate and interval: onset
    effects and drifts a single phase lag hides show here."""
    figure = Figure(figsize=(11, 3.6), layout="constrained")
    axes = figure.subplots()
    windowed = result.windowed
    if windowed is not None and windowed.count:
        axes.plot(windowed.t, windowed.latency_s * 1e3, "o-", color="grey", markersize=3,
                  label=f"per swing (sd {windowed.sd_s * 1e3:.2f} ms)")  # fmt: skip
    for index, (name, estimate) in enumerate(result.methods.items()):
        colour = f"C{index + 2}"
        axes.axhline(estimate.latency_ms, color=colour, linewidth=1, label=f"{name}: {estimate.latency_ms:.2f} ms")
        if estimate.ci95_ms is not None:
            axes.axhspan(*estimate.ci95_ms, color=colour, alpha=0.15, label=f"{name} 95 % interval")
    axes.set_xlabel("time in video (s)")
    axes.set_ylabel("latency (ms)")
    axes.set_title("latency swing by swing")
    axes.legend(**LEGEND_BESIDE)
    return figure


def residuals_figure(result: LatencyResult) -> Figure:
    """What the latency does not explain, over the whole film: the sphere less the LED delayed by
    the latency and scaled to the sphere."""
    signals = swing_signals(result.led_track, result.sphere_track)
    t, led, sphere = signals.uniform()
    delayed = np.interp(t - result.latency_ms / 1e3, t, led)
    scale = float(np.nansum(delayed * sphere) / max(np.nansum(delayed * delayed), 1e-12))
    figure = Figure(figsize=(11, 3.2), layout="constrained")
    axes = figure.subplots()
    axes.plot(t, sphere - scale * delayed, ".", markersize=1.5, color="C3", label="sphere - delayed, scaled LED")
    axes.axhline(0.0, color="k", linewidth=0.6)
    axes.set_xlabel("time in video (s)")
    axes.set_ylabel("residual (px)")
    axes.set_title("residual: structure here means the model missed something")
    axes.legend(**LEGEND_BESIDE, markerscale=6)
    return figure


def summary_figure(rows: Sequence[dict[str, Any]], group: str | None) -> Figure:
    """Latency with its interval per video, coloured by `group` (a label), and, where the videos'
    swing frequencies differ (by DISTINCT_FREQUENCIES), latency against frequency."""
    measured = [row for row in rows if row.get("latency_ms") is not None]
    frequencies = np.array([float(row["frequency_hz"]) for row in measured])
    panels = 2 if frequencies.size > 1 and np.ptp(frequencies) > DISTINCT_FREQUENCIES * np.median(frequencies) else 1
    figure = Figure(figsize=(11, 3.0 + 0.25 * len(rows) if panels == 1 else 4.5 + 0.2 * len(rows)), layout="constrained")
    axes = figure.subplots(1, panels, squeeze=False)[0]
    groups: dict[str, list[int]] = defaultdict(list)
    for index, row in enumerate(rows):
        groups[str(row.get(group, "")) if group else ""].append(index)
    per_video = axes[0]
    labelled: set[str] = set()
    for colour_index, (name, members) in enumerate(sorted(groups.items())):
        colour = f"C{colour_index}"
        for index in members:
            row = rows[index]
            if row.get("latency_ms") is None:
                per_video.annotate(f"failed: {str(row.get('error', ''))[:60]}", (0, index), xycoords=("axes fraction", "data"),
                                   fontsize=7, color="C3", va="center")  # fmt: skip
                continue
            low, high = row.get("ci95_low_ms"), row.get("ci95_high_ms")
            error = [[row["latency_ms"] - low], [high - row["latency_ms"]]] if low is not None and high is not None else None
            per_video.errorbar(row["latency_ms"], index, xerr=error, fmt="o", color=colour, capsize=3,
                               label=name if name and name not in labelled else None)  # fmt: skip
            labelled.add(name)
    per_video.set_yticks(range(len(rows)), [_short(row["video"]) for row in rows], fontsize=7)
    per_video.invert_yaxis()
    per_video.set_xlabel("latency (ms), bars: 95 % interval")
    per_video.set_ylabel("video")
    per_video.set_title("latency per video")
    if group and labelled - {""}:
        per_video.legend(title=group, **LEGEND_BESIDE)
    if panels == 2:
        against = axes[1]
        for colour_index, (name, members) in enumerate(sorted(groups.items())):
            points = [rows[i] for i in members if rows[i].get("latency_ms") is not None]
            against.errorbar([p["frequency_hz"] for p in points], [p["latency_ms"] for p in points], yerr=_interval_bars(points),
                             fmt="o", capsize=3, color=f"C{colour_index}", label=name or None)  # fmt: skip
        against.set_xlabel("pendulum swing frequency (Hz)")
        against.set_ylabel("latency (ms), bars: 95 % interval")
        against.set_title("latency against swing frequency")
        if group:
            against.legend(title=group, **LEGEND_BESIDE)
    return figure


def _interval_bars(rows: Sequence[dict[str, Any]]) -> np.ndarray:
    """Errorbar lengths below and above each row's latency (zero where it has no interval)."""
    bars = [
        (row["latency_ms"] - row["ci95_low_ms"], row["ci95_high_ms"] - row["latency_ms"])
        if row.get("ci95_low_ms") is not None and row.get("ci95_high_ms") is not None else (0.0, 0.0)
        for row in rows
    ]  # fmt: skip
    return np.array(bars, dtype=float).reshape(-1, 2).T


def _short(path: str, keep: int = 40) -> str:
    return path if len(path) <= keep else "..." + path[-keep + 3 :]
