"""`rig bench camera-calibration` (its command line declared in `rig.bench.camera_calibration_settings`): what it measures.

Each case films a calibration target (`rig.sim.flash`) with the simulated camera: a light flashing
at 50 % (or 25 %) at the frequency `analysis.shutter.suggest_flash_hz` gives for the camera, or the
display flashing full-field at a rate its refresh divides into, nearest that frequency (a display
at 59.7 Hz: its clock is not the camera's). The film is measured as a lab would (the display with
its scan-out share given), and each case's row holds the truth, the answer, its error, whether
each 95 % interval holds the truth, or the refusal, and the seconds each part took.
"""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from analysis import AnalysisError
from analysis.shutter import ShutterOptions, measure_shutter, suggest_flash_hz
from analysis.shutter.fit import largest_gap
from rig.bench.contract import Bench, Context, cell, every_one, new_figure
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.flash import FlashTarget

# The display panel tall in the frame (its height in rows sets how well its scan-out is removed),
# the LED's swing small beside it.
DISPLAY_LAYOUT = "0.06,0.5,0.05/0.58,0.5,0.76"
DISPLAY_HZ = 59.7
# Targets: the readout within this share of the truth, the exposure within that one.
READOUT_TARGET = 0.05
EXPOSURE_TARGET = 0.10
SOURCES = ("light", "light-25", "display")
PHASE_GAP = 0.1
MAX_FILM_S = 12.0


@dataclass(frozen=True)
class CalibrationGrid:
    """The cases: every camera rate, readout and exposure (shares of the frame interval; a readout
    of 0 is a global shutter) filming every source, at width x height pixels."""

    fps: tuple[float, ...] = (30.0, 60.0, 120.0, 240.0)
    readout_shares: tuple[float, ...] = (0.0, 0.3, 0.6, 0.95)
    exposure_shares: tuple[float, ...] = (0.125, 0.5, 1.0)
    sources: tuple[str, ...] = SOURCES
    width: int = 320
    height: int = 240
    seed: int = 0


QUICK_GRID = CalibrationGrid(fps=(60.0, 240.0), readout_shares=(0.6,), exposure_shares=(0.5,), sources=("light", "display"), width=160, height=120)


def case_row(grid: CalibrationGrid, fps: float, readout_s: float, exposure_s: float, source: str, seed: int, folder: Path) -> dict[str, Any]:
    """Film one case into `folder` and measure it."""
    duty = 0.25 if source == "light-25" else 0.5
    if source == "display":
        refreshes = 2 * max(1, math.ceil(DISPLAY_HZ / suggest_flash_hz(fps, exposure_s) / 2))
        flash_hz, target = DISPLAY_HZ / refreshes, FlashTarget("display", refreshes=refreshes)
    else:
        flash_hz = round(suggest_flash_hz(fps, exposure_s, duty), 2)
        target = FlashTarget("light", hz=flash_hz, duty=duty)
    camera = CameraConfig(fps=fps, exposure_s=exposure_s, readout_s=readout_s, width=grid.width, height=grid.height)
    config = SimulationConfig(
        duration_s=film_seconds(fps, flash_hz),
        camera=camera,
        display=DisplayConfig(refresh_hz=DISPLAY_HZ),
        flash=target,
        layout=DISPLAY_LAYOUT if source == "display" else "side-by-side",
        seed=seed,
    )
    row: dict[str, Any] = {"source": source, "fps": fps, "readout_ms": readout_s * 1e3, "exposure_ms": exposure_s * 1e3,
                           "duty": duty, "flash_hz": flash_hz}  # fmt: skip
    started = time.perf_counter()
    video = simulate(config, folder, overwrite=True).video_path
    row["simulate_s"] = time.perf_counter() - started
    started = time.perf_counter()
    try:
        display = {"source": "display", "display_hz": DISPLAY_HZ, "scanout_share": 1.0} if source == "display" else {}
        result = measure_shutter(video, flash_hz, ShutterOptions(duty=duty, **display))
    except AnalysisError as error:
        return row | {"refused": str(error), "estimate_s": time.perf_counter() - started}
    row["estimate_s"] = time.perf_counter() - started
    return row | _scored(result, readout_s, exposure_s)


def film_seconds(fps: float, flash_hz: float) -> float:
    """How long to film: 2 s, 120 frames and 16 flashes at least, and longer (up to MAX_FILM_S)
    until the frames have caught the flash at phases no more than PHASE_GAP apart. A display's rate
    divides its refresh, often near a multiple of the camera's, and then its phase only drifts."""
    seconds = max(2.0, 120.0 / fps, 16.0 / flash_hz)
    while seconds < MAX_FILM_S and largest_gap(flash_hz * np.arange(int(seconds * fps)) / fps) > PHASE_GAP:
        seconds = min(1.5 * seconds, MAX_FILM_S)
    return seconds


def _scored(result: Any, readout_s: float, exposure_s: float) -> dict[str, Any]:
    low, high = result.readout_ci95_s
    e_low, e_high = result.exposure_ci95_s
    readout_error = result.readout_s - readout_s
    return {
        "refused": None,
        "measured_readout_ms": float(result.readout_s) * 1e3,
        "readout_ci95_ms": [low * 1e3, high * 1e3],
        "measured_exposure_ms": result.exposure_s * 1e3,
        "exposure_ci95_ms": [e_low * 1e3, e_high * 1e3],
        "global_shutter": result.global_shutter,
        "readout_error_ms": readout_error * 1e3,
        "readout_error_pct": 100.0 * readout_error / readout_s if readout_s > 0 else None,
        "exposure_error_pct": 100.0 * (result.exposure_s - exposure_s) / exposure_s,
        "readout_within": bool(abs(readout_error) <= READOUT_TARGET * readout_s) if readout_s > 0 else result.global_shutter,
        "exposure_within": bool(abs(result.exposure_s - exposure_s) <= EXPOSURE_TARGET * exposure_s),
        "readout_covered": bool(low <= readout_s <= high),
        "exposure_covered": bool(e_low <= exposure_s <= e_high),
        "warnings": list(result.warnings),
    }


def summary(found: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per source, and over all: cases, refusals, the readout's and the exposure's median and worst
    error (%; the readout's over rolling shutters), how many are within the targets and how many
    intervals hold the truth (of those answered), and the median seconds to measure a film."""
    groups = {source: [row for row in found if row["source"] == source] for source in dict.fromkeys(row["source"] for row in found)}
    return {name: _summary(group) for name, group in {**groups, "all": found}.items()}


def _summary(group: list[dict[str, Any]]) -> dict[str, Any]:
    answered = [row for row in group if row["refused"] is None]
    rolling = [abs(row["readout_error_pct"]) for row in answered if row["readout_error_pct"] is not None]
    exposure = [abs(row["exposure_error_pct"]) for row in answered]
    return {
        "cases": len(group),
        "refused": len(group) - len(answered),
        "readout_error_pct_median": statistics.median(rolling) if rolling else None,
        "readout_error_pct_max": max(rolling) if rolling else None,
        "exposure_error_pct_median": statistics.median(exposure) if exposure else None,
        "exposure_error_pct_max": max(exposure) if exposure else None,
        "within_targets": sum(row["readout_within"] and row["exposure_within"] for row in answered),
        "covered": sum(row["readout_covered"] and row["exposure_covered"] for row in answered),
        "estimate_s_median": statistics.median(row["estimate_s"] for row in group) if group else None,
    }


def targets_met(found: list[dict[str, Any]]) -> dict[str, bool]:
    """The request's targets: every answered film's readout within 5 % and exposure within 10 %,
    from 30 to 240 fps, and every interval holding the truth."""
    answered = [row for row in found if row["refused"] is None]
    return {
        "readout within 5 % and exposure within 10 %": all(row["readout_within"] and row["exposure_within"] for row in answered),
        "every 95 % interval holds the truth": all(row["readout_covered"] and row["exposure_covered"] for row in answered),
    }


def table(report: dict[str, Any]) -> str:
    """The summaries of the report's rows as a text table."""
    summaries = summary(report["rows"])
    lines = [f"{'source':<9} {'cases':>5} {'refused':>7} {'readout err % med/max':>22} {'exposure err % med/max':>23} {'within':>6} {'covered':>7} {'s/film':>6}"]
    for name, s in summaries.items():
        lines.append(
            f"{name:<9} {s['cases']:>5} {s['refused']:>7} "
            f"{cell(s['readout_error_pct_median'], '.2f') + ' / ' + cell(s['readout_error_pct_max'], '.2f'):>22} "
            f"{cell(s['exposure_error_pct_median'], '.2f') + ' / ' + cell(s['exposure_error_pct_max'], '.2f'):>23} "
            f"{s['within_targets']:>6} {s['covered']:>7} {cell(s['estimate_s_median']):>6}"
        )
    return "\n".join(lines)


def plot(report: dict[str, Any], path: Path) -> None:
    """Seconds to measure each film against its readout's and its exposure's error, by source."""
    found = report["rows"]
    figure, axes = new_figure((10, 4.5), nrows=1, ncols=2, sharey=True)
    for source in dict.fromkeys(row["source"] for row in found):
        answered = [row for row in found if row["source"] == source and row["refused"] is None]
        rolling = [row for row in answered if row["readout_error_pct"] is not None]
        axes[0].scatter([abs(row["readout_error_pct"]) for row in rolling], [row["estimate_s"] for row in rolling], label=source, s=14)
        axes[1].scatter([abs(row["exposure_error_pct"]) for row in answered], [row["estimate_s"] for row in answered], label=source, s=14)
    for ax, what, target in ((axes[0], "readout", READOUT_TARGET), (axes[1], "exposure", EXPOSURE_TARGET)):
        ax.axvline(100 * target, color="grey", linestyle="--", linewidth=1)
        ax.set_xscale("symlog", linthresh=0.1)
        ax.set_xlabel(f"|{what} error| (%), target dashed")
    axes[0].set_ylabel("seconds to measure a film")
    axes[0].legend()
    figure.suptitle("rig calibrate-camera on simulated films, 30 to 240 fps")
    figure.tight_layout()
    figure.savefig(path, dpi=120)


def _case_text(row: dict[str, Any]) -> str:
    case = f"{row['source']} {row['fps']:g} fps, readout {row['readout_ms']:.2f} ms, exposure {row['exposure_ms']:.2f} ms, flash {row['flash_hz']:.2f} Hz"
    if row["refused"] is not None:
        return f"{case}: refused ({row['refused']})"
    return (
        f"{case}: readout {row['measured_readout_ms']:.3f} ms ({row['readout_error_ms']:+.3f}), exposure "
        f"{row['measured_exposure_ms']:.3f} ms ({row['exposure_error_pct']:+.2f} %)"
    )


def run(args: argparse.Namespace, context: Context) -> dict[str, Any]:
    """One row per case of the grid (the quick one with --quick; see the module), each filmed in its
    own folder in the context's, and how long they took."""
    started = time.perf_counter()
    grid = QUICK_GRID if args.quick else CalibrationGrid()
    cases = list(itertools.product(grid.fps, grid.readout_shares, grid.exposure_shares, grid.sources))
    found = []
    for index, (fps, readout_share, exposure_share, source) in enumerate(cases):
        folder = context.folder / f"case{index:03d}"
        row = case_row(grid, fps, readout_share / fps, exposure_share / fps, source, grid.seed + index, folder)
        context.log(f"[{index + 1}/{len(cases)}] {_case_text(row)}")
        found.append(row)
    return {"rows": found, "seconds": time.perf_counter() - started}


BENCH = Bench(
    run=run, table=table, plot=plot,
    targets=lambda report: targets_met(report["rows"]),
    all_failed=lambda report: every_one(report["rows"], "refused", "the estimate refused every one of the {count} films"),
    notes=lambda report: f"{len(report['rows'])} films in {report['seconds'] / 60:.1f} minutes",
    record=lambda report: {"summary": summary(report["rows"]), "targets_met": targets_met(report["rows"]), **report},
)
