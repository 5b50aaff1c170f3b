"""`rig bench renderers --seed-table`: the seeds' Table 2 (Smit et al. 2010, section 6.3) beside
this machine's: mean latency and its spread of the direct (reference) and the warp renderer
against scene size, measured the way the seed measured it, by filming the pendulum and analysing
the video, with the same predictor on both.

Scene sizes grow fourfold from `first` while the direct renderer's frame, measured before its run,
takes at most `max_frame_s` and the load at most `max_triangles` (memory: 36 bytes a triangle, and
the GL driver's copy). Every cost on the clock is measured (the server's modelled where the grid's
`server_ms` says, labelled). The pendulum's period may stretch to the grid's `max_period_s`: the analyser calibrates on the
first 1.5 s of video and needs the blobs to move there, so a direct renderer showing a new frame
less often than about once a second (a period over 8 s) is beyond what filming measures, as the
seed's 64M-face reference was (its latency exceeded half the pendulum's period); such a row keeps
the frame time measured before the run. Each latency is also given in display refreshes: the seed's display was a 120 Hz
stereo CRT, 60 Hz per eye, and its server's budget one 16.6 ms frame (its Table 1), so its figures
are divided by that; ours by this run's refresh. The crossover is the scene size at which the
direct renderer's latency overtakes the warp's, interpolated in log size, with the direct frame
time there: the machine-independent way to set the two tables side by side. The load is a soup
of small random triangles by default (the stress case) or a few tessellated solid objects (`load`,
meshes), what the seed's scenes were; the rows, the printed table and the plot say which, and the
warp renderer's spec.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace
from typing import Any

import numpy as np

from rig.bench import renderer_plots
from rig.bench.contract import Bench, Context, cell, given
from rig.bench.renderer_latency import check_predictors, failed_figures, film_latency
from rig.bench.renderer_rows import every_row_failed
from rig.bench.renderer_setup import machine_name, open_warp, pose_of, scene_setup
from rig.bench.renderer_specs import BenchGrid, SeedTableSpec
from rig.bench.renderers import plain, time_direct, with_options
from rig.errors import RigError
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest
from rig.sim.camera import CameraConfig

SEED_SOURCE = "Smit, van Liere, Beck, Froehlich 2010, Table 2"
SEED_REFRESH_MS = 1e3 / 60.0
SEED_TABLE_2 = (
    (64e6, None, None, 577.0, 58.9, 2.6, 14.1),
    (32e6, 780.0, 14.2, 289.0, 61.1, 2.5, 14.3),
    (16e6, 409.0, 12.3, 145.0, 62.2, 2.4, 14.6),
    (8e6, 220.0, 8.4, 72.9, 58.6, 2.8, 15.4),
    (4e6, 113.0, 5.3, 37.0, 65.4, 5.4, 16.9),
    (2e6, 68.5, 0.5, 18.8, 74.0, 3.5, 19.8),
    (1e6, 48.5, 3.5, 9.6, 71.9, 5.1, 19.7),
)
"""The seed's multi-GPU rows (faces; reference latency, sd, draw time; warp latency, sd, warp
time; ms). 64M faces: the reference's latency exceeded half the pendulum's period."""


QUICK_SPEC = SeedTableSpec(first=1_000, max_triangles=4_000, grid=BenchGrid(
    resolutions=((160, 120),), direct_frames=3, direct_budget_s=0.5, latency_camera=CameraConfig(width=320, height=240, subsamples=4),
    latency_duration_s=2.5,
))  # fmt: skip


def seed_rows() -> list[dict[str, Any]]:
    """The seed's Table 2 as rows like ours."""
    rows = []
    for faces, ref, ref_sd, ref_ms, warp, warp_sd, warp_ms in SEED_TABLE_2:
        for renderer, latency, sd, frame in (("direct", ref, ref_sd, ref_ms), ("warp", warp, warp_sd, warp_ms)):
            rows.append({
                "source": SEED_SOURCE, "renderer": renderer, "triangles": int(faces), "width": 1024, "latency_measured_ms": latency,
                "latency_sd_ms": sd, "frame_ms_median": frame, "cost_source": "measured",
                "latency_refreshes": latency / SEED_REFRESH_MS if latency is not None else None, "refresh_ms": SEED_REFRESH_MS,
            })  # fmt: skip
    return rows


def crossover(rows: list[dict[str, Any]]) -> dict[str, Any] | None:
    """Where the direct renderer's latency overtakes the warp's: the load size (log-interpolated)
    and the direct frame time there; None if it does not within the rows."""
    by = {(r["renderer"], r["triangles"]): r for r in rows if r["latency_measured_ms"] is not None}
    sizes = sorted({n for renderer, n in by if renderer == "direct" and ("warp", n) in by})
    gaps = [(n, by["direct", n]["latency_measured_ms"] - by["warp", n]["latency_measured_ms"]) for n in sizes]
    for (n0, g0), (n1, g1) in zip(gaps, gaps[1:]):
        if g0 <= 0.0 < g1:
            u = -g0 / (g1 - g0)
            f0, f1 = by["direct", n0]["frame_ms_median"], by["direct", n1]["frame_ms_median"]
            frame_ms = math.exp(math.log(f0) + u * (math.log(f1) - math.log(f0)))
            return {"triangles": float(math.exp(math.log(n0) + u * (math.log(n1) - math.log(n0)))), "direct_frame_ms": frame_ms,
                    "refresh_ms": rows[0]["refresh_ms"], "direct_frame_refreshes": frame_ms / rows[0]["refresh_ms"]}  # fmt: skip
    return None


def _probe_warp(grid: BenchGrid, setup, pendulum) -> tuple[float, float]:
    """(client s, server s) of one client frame and a few display frames, for the run's period."""
    m = open_warp(grid.warp, setup, pendulum, (1,))
    try:
        predict = pose_of(pendulum)
        client = m.renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.0, predict)).cost_s
        for k in range(4):
            t = (k + 1) / grid.refresh_hz
            m.renderer.render_display_frame(DisplayFrameRequest(k, t, t, predict, 0))
            m.wall_s.append(m.renderer.last_warp_seconds[0])
    finally:
        m.renderer.close()
    return client, float(np.median(m.wall_s[1:]))


def _row(figures: dict[str, Any], renderer: str, load: str, refresh_ms: float, machine: str) -> dict[str, Any]:
    """Our row of one renderer spec's figures on a load."""
    latency = figures["latency_measured_ms"]
    return {
        **figures, "source": "this machine", "renderer": "direct" if renderer == "direct" else "warp", "spec": renderer, "load": load,
        "latency_refreshes": latency / refresh_ms if latency is not None else None, "refresh_ms": refresh_ms, "machine": machine,
    }  # fmt: skip


def run(spec: SeedTableSpec, context: Context) -> list[dict[str, Any]]:
    """Our rows (see the module docstring), one per renderer and load size; a load that cannot be
    timed is its rows failed with the reason, and the table stops there."""
    log, runs_dir, grid = context.log, context.folder, spec.grid
    check_predictors(grid.predictor)
    machine = machine_name()
    log(f"machine: {machine}; load: {spec.load}; warp: {grid.warp}")
    rows: list[dict[str, Any]] = []
    refresh_ms = 1e3 / grid.refresh_hz
    for triangles in spec.sizes():
        try:
            setup, pendulum = scene_setup(*grid.resolutions[0], triangles, grid.refresh_hz, spec.load)
            direct_s = float(np.median(time_direct(setup, grid)[0]))
            client_s, server_s = _probe_warp(grid, setup, pendulum)
        except RigError as error:
            log(f"{triangles} triangles: not timed: {error}; the table stops here")
            for renderer in ("direct", grid.warp):
                config = grid.latency_run(renderer, triangles, grid.predictor, load=spec.load).config
                rows.append(_row(failed_figures(config, f"not timed: {error}"), renderer, spec.load, refresh_ms, machine))
            break
        if direct_s > spec.max_frame_s:
            log(f"{triangles} triangles: a direct frame takes {direct_s:.1f} s, over {spec.max_frame_s:g} s; the table stops here")
            break
        for renderer, app_s, comp_s in (("direct", direct_s, 0.0), (grid.warp, client_s, server_s)):
            started = time.perf_counter()
            run = grid.latency_run(renderer, triangles, grid.predictor, load=spec.load)
            figures = film_latency(run, app_s, comp_s, runs_dir / f"seed-{spec.load}-{renderer.replace(':', '_')}-{triangles}")
            latency = figures["latency_measured_ms"]
            if figures["frame_ms_median"] is None:
                figures["frame_ms_median"] = app_s * 1e3 if renderer == "direct" else comp_s * 1e3
            rows.append(_row(figures, renderer, spec.load, refresh_ms, machine))
            shown = f"{latency:.1f} ms (sd {figures['latency_sd_ms'] or 0:.1f})" if latency is not None else figures["latency_note"]
            log(f"{triangles:>9} triangles {renderer:8}: frame {figures['frame_ms_median'] or 0:8.1f} ms, latency {shown} "
                f"({time.perf_counter() - started:.0f} s)")  # fmt: skip
        if triangles * 4 > spec.max_triangles or direct_s * 4 > spec.max_frame_s:
            break
    return rows


def run_label(rows: list[dict[str, Any]]) -> str:
    """What our rows measured: the load's shape and the warp renderer's spec."""
    loads = "/".join(sorted({r["load"] for r in rows}))
    warps = "/".join(sorted({r["spec"] for r in rows if r["renderer"] == "warp"}))
    return f"load {loads}, warp {warps}"


def _no_crossover(rows: list[dict[str, Any]]) -> str:
    """Why a table has no crossover: which renderer was faster at every size both were measured."""
    by = {(r["renderer"], r["triangles"]): r for r in rows if r["latency_measured_ms"] is not None}
    both = sorted(n for renderer, n in by if renderer == "direct" and ("warp", n) in by)
    if not both:
        return "none: no size with both latencies measured"
    smallest = by["direct", both[0]]
    if by["direct", both[0]]["latency_measured_ms"] > by["warp", both[0]]["latency_measured_ms"]:
        return (f"below {both[0]} triangles: the warp's latency was lower already there, where a direct frame takes "
                f"{smallest['frame_ms_median']:.1f} ms ({smallest['frame_ms_median'] / smallest['refresh_ms']:.2f} refreshes)")
    return f"above {both[-1]} triangles: the direct renderer's latency was lower at every size both were measured"


def seed_table_text(rows: list[dict[str, Any]]) -> str:
    """Ours and the seed's, side by side, with each crossover."""
    sources = "; ".join(f"{renderer} {'/'.join(sorted({r['cost_source'] for r in rows if r['renderer'] == renderer}))}" for renderer in ("direct", "warp"))
    lines = [f"this machine ({run_label(rows)}; costs: {sources}; {rows[0]['width']}x{rows[0]['height']}, "
             f"{1e3 / rows[0]['refresh_ms']:g} Hz, predictor {rows[0]['predictor']}):" if rows else "this machine: no rows"]  # fmt: skip
    lines.append(f"{'triangles':>10} | {'direct frame':>12} {'latency (sd)':>16} {'/refresh':>8} | {'warp frame':>10} "
                 f"{'latency (sd)':>16} {'/refresh':>8} {'missed':>7}")  # fmt: skip
    by = {(r["renderer"], r["triangles"]): r for r in rows}
    for n in sorted({r["triangles"] for r in rows}):
        d, w = by.get(("direct", n), {}), by.get(("warp", n), {})
        lines.append(
            f"{n:>10} | {cell(d.get('frame_ms_median')):>9} ms {cell(d.get('latency_measured_ms')):>8} ({cell(d.get('latency_sd_ms'))}) "
            f"{cell(d.get('latency_refreshes'), '.2f'):>8} | {cell(w.get('frame_ms_median')):>7} ms {cell(w.get('latency_measured_ms')):>8} "
            f"({cell(w.get('latency_sd_ms'))}) {cell(w.get('latency_refreshes'), '.2f'):>8} {cell(w.get('missed_pct'), '.0f'):>6}%"
        )
    lines.append(f"{SEED_SOURCE} (2 GPUs, stereo, 60 Hz per eye; latency / {SEED_REFRESH_MS:.1f} ms):")
    for faces, ref, ref_sd, ref_ms, warp, warp_sd, warp_ms in SEED_TABLE_2:
        lines.append(
            f"{int(faces):>10} | {ref_ms:>9.1f} ms {cell(ref):>8} ({cell(ref_sd)}) {cell(ref / SEED_REFRESH_MS if ref else None, '.2f'):>8} | "
            f"{warp_ms:>7.1f} ms {warp:>8.1f} ({warp_sd}) {warp / SEED_REFRESH_MS:>8.2f}"
        )
    for name, table in (("this machine", rows), ("seed", seed_rows())):
        found = crossover(table)
        lines.append(
            f"crossover, {name}: " + (f"{found['triangles'] / 1e6:.3g}M triangles, where a direct frame takes {found['direct_frame_ms']:.1f} ms "
                                      f"({found['direct_frame_refreshes']:.2f} refreshes)" if found else _no_crossover(table))
        )  # fmt: skip
    notes = sorted({r["latency_note"] for r in rows if r.get("latency_note")})
    lines += [f"run: {note}" for note in notes]
    lines += [f"failed: {r['spec']} on {r['triangles']} triangles: {r['failed']}" for r in rows if r.get("failed")]
    return "\n".join(lines)


def spec(args: argparse.Namespace) -> SeedTableSpec:
    """The seed table's spec (the quick one with --quick), the options given over it and its grid."""
    chosen = QUICK_SPEC if args.quick else SeedTableSpec()
    return replace(chosen, grid=with_options(chosen.grid, args), **given(args, "max_frame_s", "max_triangles", "load"))


BENCH = Bench(
    spec=spec, run=run, table=seed_table_text,
    record=lambda rows: plain(rows + seed_rows()),
    plot=lambda rows, path: renderer_plots.plot_seed_table(rows, seed_rows(), path, run_label(rows)),
    all_failed=every_row_failed,
)
