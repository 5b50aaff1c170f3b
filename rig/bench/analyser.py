"""The analyser bench (`rig bench analyser`): each estimator's error, interval coverage and speed on videos of known latency.

The simulated rig films a grid of cases whose latency it knows: pendulum periods 0.6 to 1.9 s,
cameras 60 to 480 fps, displays 60 to 144 Hz, swings of 5 to 45 degrees, quality factors 20 to 500,
latencies from a predicting renderer's few ms to 450 ms (beyond half the period of a 0.6 s
pendulum, where -150 ms is as plausible), and impairments: sensor noise, defocus blur, a dim sphere, the sphere missing from 5 %
of frames. The values are spread over the cases by seeded shuffles, so every value of every axis
occurs and combinations vary; a few named cases add the hard ones (one, the unresolvable swing
filmed from its release, which the start of swing resolves).

Every case is analysed with every method. Errors are against the simulation's true latency, in
ms and in camera frame intervals; coverage is the fraction of cases whose 95 % interval holds the
truth (methods without intervals have none); cases flagged ambiguous are counted apart and left
out of the error statistics. Speed: each video is first decoded alone (the fastest the analyser's
own reader can go, nothing else done), then analysed with every method at once; a method's time
is the whole analysis less the other methods' own estimation time. A sinefit analysis runs first
(warm-up: JAX compiles once per process and clip length); sinefit's time is the faster of the two
runs, and decoding's the faster of two decodes, one before each analysis, so that a burst of load
from elsewhere on the machine touches the ratio less.

The simulated camera integrates each exposure from many instants (SUBSAMPLE_RATE per second of
exposure): with fewer, the instant inside an exposure where the display switches is rounded,
which shifts the sphere's timing by up to half a subsample (tens of microseconds at the camera's
default 8 instants per frame), a property of the simulation rather than of the analyser. The longest period is 1.9 s, not 2: the simulation's
ground truth scans delays half a period either side of its guess and, for a 2 s pendulum with a
small latency, asks the pendulum for times past the end of its simulated window.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import cv2
import numpy as np

import analysis
from analysis.video.sources import open_frames
from rig.records import VideoRecord
from rig.service import SimulationConfig, Truth, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig
from rig.sim.tracker import TrackerConfig

PERIODS_S = (0.6, 1.0, 1.4, 1.9)
CAMERA_FPS = (60.0, 120.0, 240.0, 480.0)
DISPLAY_HZ = (60.0, 90.0, 120.0, 144.0)
AMPLITUDES_DEG = (5.0, 20.0, 45.0)
QUALITIES = (20.0, 100.0, 500.0)
LATENCY_TARGETS_MS = (0.0, 40.0, 100.0, 200.0, 300.0, 450.0)
IMPAIRMENTS = ("none", "noise", "blur", "dim", "missing", "none")
DEFAULT_CASES = 48
SUBSAMPLE_RATE = 16000.0
# The rig's latency with the hold predictor and no transport delay is about this (ms); a target
# latency is reached by adding the rest as tracker transport delay.
HOLD_BASE_MS = 38.0
NOISE_DN = 8.0
BLUR_SIGMA_PX = 2.5
DIM_WHITE_DN = 45.0
MISSING_FRACTION = 0.05
TARGETS = {"median_frames": 0.1, "worst_frames": 0.5, "coverage": (0.90, 0.98), "speed_ratio": 0.8}

Log = Callable[[str], None]


@dataclass(frozen=True)
class Case:
    """One simulated video: its rig, the latency aimed at, and what is done to the video afterwards."""

    name: str
    config: SimulationConfig
    target_ms: float
    impairment: str


def _config(
    period: float,
    fps: float,
    display: float,
    amplitude: float,
    quality: float,
    target_ms: float,
    impairment: str,
    seed: int,
    release_s: float | None = None,
) -> SimulationConfig:
    predictor = "slerp" if target_ms == 0.0 else "hold"
    transport = 0.004 if target_ms == 0.0 else max(0.0, target_ms - HOLD_BASE_MS) / 1e3
    camera = CameraConfig(
        fps=fps,
        subsamples=max(8, math.ceil(SUBSAMPLE_RATE / fps)),
        noise_dn=NOISE_DN if impairment == "noise" else CameraConfig().noise_dn,
        display_white_dn=DIM_WHITE_DN if impairment == "dim" else CameraConfig().display_white_dn,
    )
    return SimulationConfig(
        duration_s=max(6.0, 4.0 * period),
        seed=seed,
        pendulum=PendulumConfig(period_s=period, amplitude_deg=amplitude, quality=quality, release_s=release_s),
        tracker=TrackerConfig(transport_delay_s=transport),
        display=DisplayConfig(refresh_hz=display),
        camera=camera,
        predictor=predictor,
        warmup_s=0.5 + transport,
    )


def _case(
    index: int,
    period: float,
    fps: float,
    display: float,
    amplitude: float,
    quality: float,
    target: float,
    impairment: str,
    label: str = "",
    release_s: float | None = None,
) -> Case:
    name = label or f"case{index:02d}"
    released = f" released at {release_s:g}s" if release_s is not None else ""
    description = (
        f"{name}: T={period:g}s {fps:g}fps {display:g}Hz {amplitude:g}deg Q={quality:g} "
        f"target {target:g}ms {impairment}{released}"
    )
    config = _config(period, fps, display, amplitude, quality, target, impairment, index, release_s)
    return Case(description, config, target, impairment)


def grid(count: int = DEFAULT_CASES, seed: int = 0) -> list[Case]:
    """``count`` mixed cases (every axis value shuffled over them), then the named hard cases."""
    rng = np.random.default_rng(seed)

    def spread(values: tuple[Any, ...]) -> list[Any]:
        repeated = [values[i % len(values)] for i in range(count)]
        return [repeated[i] for i in rng.permutation(count)]

    axes = [spread(axis) for axis in (PERIODS_S, CAMERA_FPS, DISPLAY_HZ, AMPLITUDES_DEG, QUALITIES, LATENCY_TARGETS_MS, IMPAIRMENTS)]
    cases = [_case(i, *values) for i, values in enumerate(zip(*axes, strict=True))]
    named = [
        (0.6, 240.0, 60.0, 20.0, 20.0, 450.0, "none", "beyond-half-damped"),
        (0.6, 120.0, 144.0, 45.0, 50.0, 450.0, "none", "beyond-half-wide"),
        (0.6, 240.0, 60.0, 5.0, 500.0, 450.0, "none", "beyond-half-unresolvable"),
        (1.0, 240.0, 60.0, 20.0, 200.0, 480.0, "none", "near-half-period"),
        (0.6, 240.0, 60.0, 5.0, 500.0, 450.0, "none", "beyond-half-filmed-release", 1.0),
    ]
    return cases + [_case(count + i, *values) for i, values in enumerate(named)]


def quick_grid() -> list[Case]:
    """Two short, cheap cases for a smoke test."""
    cases = [
        _case(0, 0.6, 60.0, 60.0, 20.0, 50.0, 40.0, "none", "quick-a"),
        _case(1, 0.6, 60.0, 120.0, 30.0, 20.0, 100.0, "missing", "quick-b"),
    ]
    return [replace(case, config=replace(case.config, duration_s=3.0)) for case in cases]


def _rewrite(video: Path, out: Path, change: Callable[[int, np.ndarray], np.ndarray], fps: float) -> Path:
    """Write ``video``'s frames, changed, to ``out`` as the simulated camera writes them."""
    source = open_frames(video)
    writer = VideoRecord(out, fps, *source.frame_size)
    with writer:
        for index, (_, frame) in enumerate(source.frames()):
            writer.write(change(index, frame))
    return out


def impaired(video: Path, case: Case, truth: Truth, seed: int) -> Path:
    """The case's video after its impairment (the original for those the simulation makes itself)."""
    fps = case.config.camera.fps
    if case.impairment == "blur":
        return _rewrite(video, video.with_name("blurred.avi"), lambda _, f: cv2.GaussianBlur(f, (0, 0), BLUR_SIGMA_PX), fps)
    if case.impairment == "missing":
        x, y, w, h = truth.sphere_roi
        frames = [frame for _, frame in open_frames(video).frames()]
        background = np.median(np.stack([f[y : y + h, x : x + w] for f in frames[:: max(1, len(frames) // 31)]]), axis=0)
        hidden = set(np.random.default_rng(seed).choice(len(frames), round(MISSING_FRACTION * len(frames)), replace=False).tolist())

        def hide(index: int, frame: np.ndarray) -> np.ndarray:
            if index not in hidden:
                return frame
            frame = frame.copy()
            frame[y : y + h, x : x + w] = background.astype(np.uint8)
            return frame

        return _rewrite(video, video.with_name("missing.avi"), hide, fps)
    return video


def decode_seconds(video: Path) -> tuple[float, int]:
    """Time to decode every frame with the analyser's reader, doing nothing else; and the frame count."""
    started = time.perf_counter()
    count = sum(1 for _ in open_frames(video).frames())
    return time.perf_counter() - started, count


def run_case(case: Case, folder: Path, log: Log) -> dict[str, Any]:
    """Simulate, impair, decode and analyse one case; one JSON-ready row."""
    started = time.perf_counter()
    run = simulate(case.config, folder, overwrite=True)
    truth_ms = float(run.truth.latency_ms)
    video = impaired(run.video_path, case, run.truth, case.config.seed)
    simulated = time.perf_counter() - started
    first_decode, frames = decode_seconds(video)
    warm_started = time.perf_counter()
    analysis.analyse(video, method="sinefit")
    warm_s = time.perf_counter() - warm_started
    second_decode, _ = decode_seconds(video)
    decode_s = min(first_decode, second_decode)
    analysed_started = time.perf_counter()
    result = analysis.analyse(video, method="all", seed=case.config.seed)
    total_s = time.perf_counter() - analysed_started
    frame_ms = 1e3 / case.config.camera.fps
    estimation = sum(m.seconds for m in result.methods.values())
    methods = {}
    for name, estimate in result.methods.items():
        seconds = total_s - estimation + estimate.seconds
        if name == "sinefit":
            seconds = min(seconds, warm_s)
        if name == "bayes":
            # The posterior starts from the fit: its time includes the fit's.
            seconds += result.methods["sinefit"].seconds
        error = estimate.latency_ms - truth_ms
        ci = estimate.ci95_ms
        methods[name] = {
            "latency_ms": estimate.latency_ms,
            "error_ms": error,
            "error_frames": error / frame_ms,
            "ci95_ms": list(ci) if ci is not None else None,
            "covered": None if ci is None else bool(ci[0] <= truth_ms <= ci[1]),
            "seconds": seconds,
            "fps": frames / seconds,
            "speed_ratio": decode_s / seconds,
            "model": estimate.model,
        }
    row = {
        "case": case.name,
        "period_s": case.config.pendulum.period_s,
        "camera_fps": case.config.camera.fps,
        "display_hz": case.config.display.refresh_hz,
        "amplitude_deg": case.config.pendulum.amplitude_deg,
        "quality": case.config.pendulum.quality,
        "impairment": case.impairment,
        "predictor": case.config.predictor,
        "truth_ms": truth_ms,
        "frames": frames,
        "ambiguous": result.ambiguous,
        "cycles": result.cycles.to_dict(),
        "decode_s": decode_s,
        "decode_fps": frames / decode_s,
        "warm_up_s": warm_s,
        "simulate_s": simulated,
        "methods": methods,
        "warnings": result.warnings,
    }
    sinefit = methods["sinefit"]
    log(
        f"{case.name}: truth {truth_ms:.2f} ms, sinefit {sinefit['error_ms']:+.3f} ms "
        f"({sinefit['error_frames']:+.3f} frames){' AMBIGUOUS' if result.ambiguous else ''}, "
        f"speed x{sinefit['speed_ratio']:.2f} of decoding ({time.perf_counter() - started:.0f} s)"
    )
    return row


def summarise(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per method: error statistics over unambiguous cases, interval coverage, speed."""
    summary = {}
    decode_total = sum(row["decode_s"] for row in rows)
    for name in analysis.methods():
        clear = [row["methods"][name] for row in rows if not row["ambiguous"]]
        errors_ms = np.abs([m["error_ms"] for m in clear])
        errors_frames = np.abs([m["error_frames"] for m in clear])
        covered = [m["covered"] for m in clear if m["covered"] is not None]
        seconds = sum(row["methods"][name]["seconds"] for row in rows)
        summary[name] = {
            "cases": len(rows),
            "unambiguous": len(clear),
            "median_abs_error_ms": float(np.median(errors_ms)) if clear else None,
            "median_abs_error_frames": float(np.median(errors_frames)) if clear else None,
            "worst_abs_error_ms": float(np.max(errors_ms)) if clear else None,
            "worst_abs_error_frames": float(np.max(errors_frames)) if clear else None,
            "coverage": float(np.mean(covered)) if covered else None,
            "intervals": len(covered),
            "analysis_fps": sum(row["frames"] for row in rows) / seconds,
            "speed_ratio": decode_total / seconds,
            "median_speed_ratio": float(np.median([row["methods"][name]["speed_ratio"] for row in rows])),
        }
    return summary


def targets_met(summary: dict[str, dict[str, Any]]) -> dict[str, bool | None]:
    """The issue's targets for sinefit (and bayes's coverage)."""
    fit, bayes = summary["sinefit"], summary["bayes"]
    low, high = TARGETS["coverage"]

    def within(value: float | None) -> bool | None:
        return None if value is None else low <= value <= high

    return {
        "sinefit_median_le_0.1_frames": fit["median_abs_error_frames"] is not None and fit["median_abs_error_frames"] <= TARGETS["median_frames"],
        "sinefit_worst_le_0.5_frames": fit["worst_abs_error_frames"] is not None and fit["worst_abs_error_frames"] <= TARGETS["worst_frames"],
        "sinefit_coverage_90_98": within(fit["coverage"]),
        "bayes_coverage_90_98": within(bayes["coverage"]),
        "sinefit_speed_ge_0.8_of_decoding": fit["speed_ratio"] >= TARGETS["speed_ratio"],
    }


def table(summary: dict[str, dict[str, Any]]) -> str:
    """The summary as a Markdown table (the README's)."""

    def cell(value: Any, digits: int) -> str:
        return "-" if value is None else f"{value:.{digits}f}"

    lines = [
        "| method | median abs error (ms / frames) | worst abs error (ms / frames) | 95% coverage | analysis fps | speed vs decoding |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for name, s in summary.items():
        coverage = "-" if s["coverage"] is None else f"{s['coverage']:.0%} of {s['intervals']}"
        lines.append(
            f"| {name} | {cell(s['median_abs_error_ms'], 3)} / {cell(s['median_abs_error_frames'], 3)} | "
            f"{cell(s['worst_abs_error_ms'], 3)} / {cell(s['worst_abs_error_frames'], 3)} | {coverage} | "
            f"{s['analysis_fps']:.0f} | x{s['speed_ratio']:.2f} |"
        )
    return "\n".join(lines)


def plot(summary: dict[str, dict[str, Any]], rows: list[dict[str, Any]], path: Path) -> None:
    """Speed against error, per method: every case faint, the method's median and worst bold."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8, 5.5))
    axes = figure.subplots()
    for index, (name, s) in enumerate(summary.items()):
        colour = f"C{index}"
        clear = [row for row in rows if not row["ambiguous"]]
        axes.scatter(
            [row["methods"][name]["speed_ratio"] for row in clear],
            [max(abs(row["methods"][name]["error_frames"]), 1e-4) for row in clear],
            s=10, alpha=0.3, color=colour,
        )  # fmt: skip
        if s["median_abs_error_frames"] is not None:
            axes.errorbar(
                [s["speed_ratio"]],
                [s["median_abs_error_frames"]],
                yerr=[[0.0], [s["worst_abs_error_frames"] - s["median_abs_error_frames"]]],
                fmt="o", color=colour, capsize=4, markersize=8,
                label=f"{name}: median {s['median_abs_error_frames']:.3f}, worst {s['worst_abs_error_frames']:.2f} frames",
            )  # fmt: skip
    axes.axhline(TARGETS["median_frames"], color="grey", linestyle=":", linewidth=1)
    axes.axhline(TARGETS["worst_frames"], color="grey", linestyle="--", linewidth=1)
    axes.axvline(TARGETS["speed_ratio"], color="grey", linestyle="-.", linewidth=1)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("analysis speed / decoding speed (same video)")
    axes.set_ylabel("|error| in camera frame intervals")
    axes.set_title(f"rig bench analyser: {len(rows)} simulated videos of known latency")
    axes.legend(loc="lower left", fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def run_bench(cases: list[Case], folder: Path, log: Log) -> dict[str, Any]:
    rows = []
    for index, case in enumerate(cases):
        log(f"[{index + 1}/{len(cases)}] {case.name}")
        rows.append(run_case(case, folder / f"case{index:03d}", log))
    summary = summarise(rows)
    return {"summary": summary, "targets_met": targets_met(summary), "cases": rows}
