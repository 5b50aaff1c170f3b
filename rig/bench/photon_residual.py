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
from dataclasses import dataclass, replace
from typing import Any

from rig.bench.contract import Bench, Context, cell
from rig.bench.renderer_latency import check_predictors, film_latency
from rig.bench.renderer_rows import every_row_failed
from rig.bench.renderer_setup import machine_name
from rig.bench.renderer_specs import BenchGrid
from rig.bench.renderers import plain, with_options
from rig.session import DEFAULT_SERVER_MS, PHOTON_TARGETS

RESIDUAL_PREDICTORS = ("rls", "adaptive", "kalman-ca", "kalman-cv", "desp", "slerp", "hold")
RESIDUAL_TRIANGLES = 10_000


@dataclass(frozen=True)
class ResidualSpec:
    """The grid (its first resolution, refresh, films' camera and length, and `server_ms`) and the predictors filmed."""

    grid: BenchGrid
    predictors: tuple[str, ...]


def run(spec: ResidualSpec, context: Context) -> list[dict[str, Any]]:
    """A row per predictor and photon target, the server's cost modelled at DEFAULT_SERVER_MS (or
    the grid's `server_ms`)."""
    grid = replace(spec.grid, server_ms=spec.grid.server_ms if spec.grid.server_ms is not None else DEFAULT_SERVER_MS)
    check_predictors(*spec.predictors)
    machine = machine_name()
    rows = []
    for predictor in spec.predictors:
        for target in PHOTON_TARGETS:
            started = time.perf_counter()
            run = grid.latency_run("warp", RESIDUAL_TRIANGLES, predictor, target)
            figures = film_latency(run, 0.05, grid.server_ms / 1e3, context.folder / f"residual-{predictor}-{target}")
            rows.append({**figures, "machine": machine})
            measured = figures["latency_measured_ms"]
            context.log(f"{predictor:10} {target:8}: latency {measured if measured is not None else float('nan'):+.2f} ms measured, "
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
        cells = [cell(by.get((predictor, target), {}).get(name), "+.2f") for target in PHOTON_TARGETS
                 for name in ("latency_measured_ms", "latency_true_ms")]  # fmt: skip
        lines.append(f"{predictor:10} {cells[0]:>15} ms {cells[1]:>8} {cells[2]:>15} ms {cells[3]:>8}")
    best = best_predictor(rows)
    if best is not None:
        aimed, scanout = by[best, "photons"], by.get((best, "scanout"), {})
        lines.append(f"best predictor {best}: residual {aimed['latency_measured_ms']:+.2f} ms aimed at the photons, "
                     f"{scanout.get('latency_measured_ms') or float('nan'):+.2f} ms aimed at scan-out")  # fmt: skip
    lines += [f"run: {note}" for note in sorted({r["latency_note"] for r in rows if r.get("latency_note")})]
    lines += [f"failed: {r['predictor']} aimed at {r['photon_target']}: {r['failed']}" for r in rows if r.get("failed")]
    return "\n".join(lines)


BENCH = Bench(
    spec=lambda args: ResidualSpec(with_options(args.spec, args), tuple(args.residual_predictor or RESIDUAL_PREDICTORS)),
    run=run, table=residual_text, record=plain, all_failed=every_row_failed,
)
