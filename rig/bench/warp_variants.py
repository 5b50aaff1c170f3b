"""`rig bench renderers --variants`: image error against latency saved, for each warp variant and scene.

For each load size, the direct renderer's latency is filmed once; then each warp variant (a spec,
`warp:recon=grid`, ...) is measured three ways: its image error against a direct render at the same
pose (client frames at several swing phases, each warped over a client:display rate ratio of 1:r,
as the renderer bench does: Lab > 10 share, SSIM, DSSIM, holes left for the fill), its cost per
display frame and primitives, and its latency, filmed with every cost measured (or the server's
modelled, labelled). Latency saved is the direct renderer's latency less the variant's, both
measured from video; a variant whose server misses refreshes saves less. One picture then shows
what each variant costs in image quality for the latency it saves.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rig.bench import renderer_plots
from rig.bench.contract import Bench, Context, cell, given
from rig.bench.renderer_latency import check_predictors, failed_figures, film_latency
from rig.bench.renderer_rows import every_row_failed
from rig.bench.renderer_setup import QUALITY_FIGURES, machine_name, open_warp, scene_setup, warp_renderer
from rig.bench.renderer_specs import BenchGrid
from rig.bench.renderers import measure_warp_quality, plain, time_direct, time_warp_rounds, with_options
from rig.errors import RigError

DEFAULT_VARIANTS = (
    "warp", "warp:recon=quad", "warp:recon=mesh", "warp:recon=grid", "warp:views=2", "warp:holes=1", "warp:holes=2",
    "warp:fill=lowpass", "warp:views=2,recon=grid,holes=2,fill=lowpass", "warp:spin=30", "warp:spin=30,untracked=hold",
)  # fmt: skip
QUICK_VARIANTS = ("warp", "warp:views=2,recon=grid,holes=1")


@dataclass(frozen=True)
class VariantSpec:
    """What `--variants` measures: the variants, what the load makes, and the grid whose load sizes,
    first resolution, first rate ratio (of the image error), timing and films (predictor, costs) it takes."""

    variants: tuple[str, ...] = DEFAULT_VARIANTS
    load: str = "soup"
    """what the load's triangles make (`rig.render.gl.LOAD_SHAPES`): the soup is the stress case of
    the warp's reconstructions (visible fragments a few pixels wide), meshes what real scenes are"""
    grid: BenchGrid = BenchGrid(triangles=(10_000, 200_000), resolutions=((320, 240),), ratios=(5,), phases=2, warp_rounds=8,
                                direct_frames=3, direct_budget_s=2.0)  # fmt: skip
    """a cheap scene and one whose direct frames take several refreshes, still within what filming measures"""


def spec(args: argparse.Namespace) -> VariantSpec:
    """The variants' spec, the options given over it and its grid; with --quick a tiny run: one load,
    two variants, the quick grid (`args.spec`, read) at one rate ratio."""
    chosen = VariantSpec(QUICK_VARIANTS, grid=replace(args.spec, triangles=(1_000,), ratios=(3,))) if args.quick else VariantSpec()
    return replace(chosen, grid=with_options(chosen.grid, args), **given(args, "load"), **({"variants": tuple(args.variant)} if args.variant else {}))


def untimed_row(spec: VariantSpec, variant: str, triangles: int, reason: str, machine: str) -> dict[str, Any]:
    """The row of a variant on a load that could not be timed: no figures, failed with `reason`."""
    run = spec.grid.latency_run(variant, triangles, spec.grid.predictor, load=spec.load)
    return {
        **failed_figures(run.config, reason), **dict.fromkeys(QUALITY_FIGURES), "spec": variant, "renderer": "warp",
        "rate_ratio": spec.grid.ratios[0], "load": spec.load, "server_ms_median": None, "client_ms_median": None,
        "direct_latency_ms": None, "latency_saved_ms": None, "machine": machine,
    }  # fmt: skip


def run(spec: VariantSpec, context: Context) -> list[dict[str, Any]]:
    """A row per variant and load size (see the module docstring); a load or variant that cannot be
    timed is its row failed with the reason, and the others still run."""
    log, runs_dir = context.log, context.folder
    for variant in spec.variants:
        warp_renderer(variant)
    check_predictors(spec.grid.predictor)
    machine = machine_name()
    log(f"machine: {machine}; load: {spec.load}")
    grid = spec.grid
    size, ratio = grid.resolutions[0], grid.ratios[0]
    rows: list[dict[str, Any]] = []
    for triangles in grid.triangles:
        try:
            setup, pendulum = scene_setup(*size, triangles, grid.refresh_hz, spec.load)
            direct_s = float(np.median(time_direct(setup, grid)[0]))
        except RigError as error:
            log(f"{triangles:>9} triangles: not timed: {error}")
            rows += [untimed_row(spec, variant, triangles, f"not timed: {error}", machine) for variant in spec.variants]
            continue
        direct_run = grid.latency_run("direct", triangles, grid.predictor, load=spec.load)
        direct = film_latency(direct_run, direct_s, 0.0, runs_dir / f"variants-direct-{triangles}")
        log(f"{triangles:>9} triangles: direct latency {direct['latency_measured_ms'] or float('nan'):.1f} ms")
        for variant in spec.variants:
            started = time.perf_counter()
            try:
                m = open_warp(variant, setup, pendulum, grid.ratios)
                try:
                    measure_warp_quality(m, grid)
                    time_warp_rounds([m], grid)
                finally:
                    m.renderer.close()
            except RigError as error:
                log(f"{triangles:>9} triangles {variant:45}: not timed: {error}")
                rows.append(untimed_row(spec, variant, triangles, f"not timed: {error}", machine))
                continue
            client_s, server_s = float(np.median(m.client_s)), float(np.median(m.wall_s))
            run = grid.latency_run(variant, triangles, grid.predictor, load=spec.load)
            figures = film_latency(run, client_s, server_s, runs_dir / f"variants-{variant.replace(':', '_').replace(',', '_')}-{triangles}")
            warp_ms, direct_ms = figures["latency_measured_ms"], direct["latency_measured_ms"]
            rows.append({
                **figures, **m.quality(ratio), "spec": variant, "renderer": "warp", "rate_ratio": ratio, "load": spec.load,
                "server_ms_median": server_s * 1e3, "client_ms_median": client_s * 1e3,
                "direct_latency_ms": direct_ms,
                "latency_saved_ms": direct_ms - warp_ms if warp_ms is not None and direct_ms is not None else None,
                "machine": machine,
            })  # fmt: skip
            r = rows[-1]
            log(f"{triangles:>9} triangles {variant:45}: Lab>10 {r['lab_error_pct']:.3f} %, SSIM {r['ssim']:.4f}, "
                f"{r['primitives']:.0f} primitives, {server_s * 1e3:.1f} ms/frame, latency {warp_ms or float('nan'):.1f} ms "
                f"({time.perf_counter() - started:.0f} s)")  # fmt: skip
    return rows


def variants_text(rows: list[dict[str, Any]]) -> str:
    """The rows as a table."""
    header = (f"{'N':>9} {'variant':45} {'Lab>10 %':>8} {'SSIM':>7} {'DSSIM':>7} {'holes %':>7} {'primitives':>10} "
              f"{'ms/frame':>8} {'missed':>6} {'latency':>8} {'saved':>7}")  # fmt: skip
    lines = [header]
    for r in rows:
        if r["server_ms_median"] is None:
            lines.append(f"{r['triangles']:>9} {r['spec']:45} failed: {r['failed']}")
            continue
        figures = [cell(r[name], ".3f") for name in ("lab_error_pct", "ssim", "dssim", "hole_pct")]
        latency, saved = cell(r["latency_measured_ms"]), cell(r["latency_saved_ms"])
        lines.append(
            f"{r['triangles']:>9} {r['spec']:45} {figures[0]:>8} {figures[1]:>7} {figures[2]:>7} {figures[3]:>7} {r['primitives']:>10.0f} "
            f"{r['server_ms_median']:>8.1f} {r['missed_pct'] or 0:>5.0f}% {latency:>8} {saved:>7}"
        )
    lines.append(f"image figures: means over the warped frames (client:display 1:{rows[0]['rate_ratio']}); "
                 f"{', '.join(QUALITY_FIGURES)}" if rows else "no rows")  # fmt: skip
    films_failed = [r for r in rows if r["failed"] and r["server_ms_median"] is not None]
    lines += [f"failed: {r['spec']} on {r['triangles']} triangles: {r['failed']}" for r in films_failed]
    return "\n".join(lines)


BENCH = Bench(
    spec=spec, run=run, table=variants_text, record=plain, plot=renderer_plots.plot_variants, all_failed=every_row_failed,
)
