"""`rig bench renderers --photon-residual`: how close to zero prediction brings the measured latency.

The warp renderer with a GPU-like server cost (modelled, DEFAULT_SERVER_MS, labelled) is filmed
with each predictor twice: poses predicted for the middle of the interval the sphere's row emits
each frame (scan-out plus half the persistence: the photon target) and for the moment scan-out
reaches the row (the scan-out target). A perfect predictor aimed at the photons leaves no latency
for the analyser to find, since the display's sample-and-hold then straddles the true position
symmetrically; what remains is the predictor's error over its horizon. The best predictor is the one
whose photon-target latency lies nearest zero.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable

from rig.bench.renderer_latency import LatencyRun, film_latency
from rig.bench.renderers import BenchGrid, machine_name
from rig.session import DEFAULT_SERVER_MS, PHOTON_TARGETS

RESIDUAL_PREDICTORS = ("adaptive", "kalman-ca", "kalman-cv", "desp", "slerp", "hold")
RESIDUAL_TRIANGLES = 10_000

Log = Callable[[str], None]


def run_photon_residual(grid: BenchGrid, predictors: tuple[str, ...], runs_dir: Path, log: Log) -> list[dict[str, Any]]:
    """A row per predictor and photon target, the server's cost modelled at DEFAULT_SERVER_MS (or
    the grid's `server_ms`)."""
    machine = machine_name()
    server_ms = grid.server_ms if grid.server_ms is not None else DEFAULT_SERVER_MS
    rows = []
    for predictor in predictors:
        for target in PHOTON_TARGETS:
            started = time.perf_counter()
            run = LatencyRun(
                "warp", RESIDUAL_TRIANGLES, grid.resolutions[0], predictor, server_ms=server_ms, photon_target=target,
                refresh_hz=grid.refresh_hz, camera=grid.latency_camera, min_duration_s=grid.latency_duration_s,
                max_period_s=grid.max_period_s,
            )  # fmt: skip
            figures = film_latency(run, 0.05, server_ms / 1e3, runs_dir / f"residual-{predictor}-{target}")
            rows.append({**figures, "machine": machine})
            measured = figures["latency_measured_ms"]
            log(f"{predictor:10} {target:8}: latency {measured if measured is not None else float('nan'):+.2f} ms measured, "
                f"{figures['latency_true_ms'] or float('nan'):+.2f} ms true ({time.perf_counter() - started:.0f} s)")  # fmt: skip
    return rows


def best_predictor(rows: list[dict[str, Any]]) -> str | None:
    """The predictor whose photon-target latency, as measured, lies nearest zero."""
    aimed = [r for r in rows if r["photon_target"] == "photons" and r["latency_measured_ms"] is not None]
    return min(aimed, key=lambda r: abs(r["latency_measured_ms"]))["predictor"] if aimed else None


def residual_text(rows: list[dict[str, Any]]) -> str:
    """Each predictor's latency with both targets, and the best one's residual."""
    by = {(r["predictor"], r["photon_target"]): r for r in rows}
    lines = [f"{'predictor':10} {'photons: measured':>18} {'true':>8} {'scanout: measured':>18} {'true':>8}"]
    for predictor in dict.fromkeys(r["predictor"] for r in rows):
        cells = []
        for target in PHOTON_TARGETS:
            r = by.get((predictor, target), {})
            cells += [f"{r.get('latency_measured_ms'):+.2f}" if r.get("latency_measured_ms") is not None else "-",
                      f"{r.get('latency_true_ms'):+.2f}" if r.get("latency_true_ms") is not None else "-"]  # fmt: skip
        lines.append(f"{predictor:10} {cells[0]:>15} ms {cells[1]:>8} {cells[2]:>15} ms {cells[3]:>8}")
    best = best_predictor(rows)
    if best is not None:
        aimed, scanout = by[best, "photons"], by.get((best, "scanout"), {})
        lines.append(f"best predictor {best}: residual {aimed['latency_measured_ms']:+.2f} ms aimed at the photons, "
                     f"{scanout.get('latency_measured_ms') or float('nan'):+.2f} ms aimed at scan-out")  # fmt: skip
    lines += [f"run: {note}" for note in sorted({r["latency_note"] for r in rows if r.get("latency_note")})]
    return "\n".join(lines)
