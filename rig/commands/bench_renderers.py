"""`rig bench renderers`: the renderer bench's options, and what it prints and writes.

Four kinds of run: the grid (cost, latency and image error of the direct and the warp renderer
against scene size and resolution, `rig.bench.renderers`; a spec file, the options over it),
`--seed-table` (the seeds' Table 2 beside this machine's, `rig.bench.seed_table`), `--variants`
(image error against latency saved per warp variant, `rig.bench.warp_variants`) and
`--photon-residual` (how near zero prediction brings the latency, `rig.bench.photon_residual`).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Iterator

from rig.bench import photon_residual, renderer_plots, renderer_report, renderers, seed_table, warp_variants
from rig.bench.renderers import BenchGrid
from rig.commands import options, outputs
from rig.render.gl import LOAD_SHAPES


def _log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _int_list(text: str) -> tuple[int, ...]:
    values = tuple(options.non_negative_int(part) for part in text.split(","))
    if not values:
        raise argparse.ArgumentTypeError(f"expected a comma-separated list of whole numbers, got {text!r}")
    return values


def _ratio_list(text: str) -> tuple[int, ...]:
    values = _int_list(text)
    if min(values) < 1:
        raise argparse.ArgumentTypeError(f"rate ratios are display frames per client frame, at least 1, got {text!r}")
    return values


def _resolution(text: str) -> tuple[int, int]:
    w, sep, h = text.lower().partition("x")
    try:
        size = (int(w), int(h))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {text!r}") from None
    if not sep or min(size) < 16:
        raise argparse.ArgumentTypeError(f"a resolution is WIDTHxHEIGHT, each at least 16, got {text!r}")
    return size


def _resolution_list(text: str) -> tuple[tuple[int, int], ...]:
    return tuple(_resolution(part) for part in text.split(","))


@contextmanager
def _runs_folder(runs: Path | None) -> Iterator[Path]:
    """Where the latency runs' videos go: `runs`, or a temporary folder removed afterwards."""
    if runs is not None:
        runs.mkdir(parents=True, exist_ok=True)
        yield runs
        return
    with tempfile.TemporaryDirectory(prefix="rig-bench-") as scratch:
        yield Path(scratch)


_GRID_OPTIONS = ("triangles", "resolutions", "ratios", "warp", "server_ms", "predictor", "direct_predictor")


def _grid(args: argparse.Namespace) -> BenchGrid:
    """The spec's grid (the quick one with --quick), with the options given over it."""
    grid = renderers.read_grid(renderers.QUICK_SPEC if args.quick else args.spec)
    return replace(grid, **{name: getattr(args, name) for name in _GRID_OPTIONS if getattr(args, name) is not None})


def _seed_table(args: argparse.Namespace, runs: Path) -> tuple[list[dict], str]:
    spec = seed_table.QUICK_SPEC if args.quick else seed_table.SeedTableSpec()
    spec = replace(spec, server_ms=args.server_ms, max_frame_s=args.max_frame_s,
                   max_triangles=args.max_triangles if args.max_triangles is not None else spec.max_triangles,
                   **({"predictor": args.predictor} if args.predictor else {}),
                   **({"warp": args.warp} if args.warp else {}), **({"load": args.load} if args.load else {}),
                   **({"size": args.resolutions[0]} if args.resolutions else {}))  # fmt: skip
    rows = seed_table.run_seed_table(spec, runs, _log)
    if args.plot is not None:
        renderer_plots.plot_seed_table(rows, seed_table.seed_rows(), args.plot, seed_table.run_label(rows))
    return rows + seed_table.seed_rows(), seed_table.seed_table_text(rows)


def _variants(args: argparse.Namespace, runs: Path) -> tuple[list[dict], str]:
    spec = warp_variants.quick_spec() if args.quick else warp_variants.VariantSpec()
    grid = replace(spec.grid, server_ms=args.server_ms, **({"resolutions": args.resolutions[:1]} if args.resolutions else {}))
    spec = replace(spec, grid=grid, **({"predictor": args.predictor} if args.predictor else {}),
                   **({"variants": tuple(args.variant)} if args.variant else {}),
                   **({"triangles": args.triangles} if args.triangles else {}), **({"load": args.load} if args.load else {}))  # fmt: skip
    rows = warp_variants.run_variants(spec, runs, _log)
    if args.plot is not None:
        renderer_plots.plot_variants(rows, args.plot)
    return rows, warp_variants.variants_text(rows)


def _photon_residual(args: argparse.Namespace, runs: Path) -> tuple[list[dict], str]:
    chosen = tuple(args.residual_predictor) if args.residual_predictor else photon_residual.RESIDUAL_PREDICTORS
    rows = photon_residual.run_photon_residual(_grid(args), chosen, runs, _log)
    return rows, photon_residual.residual_text(rows)


def _run(args: argparse.Namespace) -> int:
    writes = outputs.LateWrites()
    with _runs_folder(args.runs) as runs:
        if args.seed_table:
            rows, text = _seed_table(args, runs)
        elif args.variants:
            rows, text = _variants(args, runs)
        elif args.photon_residual:
            rows, text = _photon_residual(args, runs)
        else:
            rows = renderers.run_bench(_grid(args), runs, _log, args.workers, args.scheduler)
            if args.plot is not None:
                writes.write(args.plot, lambda: renderer_plots.plot_rows(rows, args.plot))
            text = renderer_report.table(rows)
    if args.json is not None:
        writes.write(args.json, lambda: renderer_report.write_json(rows, args.json))
    if args.csv is not None:
        writes.write(args.csv, lambda: renderer_report.write_csv(rows, args.csv))
    print(text)
    writes.check()
    return 0


def add_renderers(benchmarks: argparse._SubParsersAction) -> None:
    parser = benchmarks.add_parser(
        "renderers",
        help="frame cost, latency and image error of the direct and warp renderers against scene size",
        description="Time the direct renderer and the warp renderer's client and server for load sizes and display "
        "resolutions, measure the image error of warped frames against direct renders, and the latency `rig analyse` "
        "finds in simulated videos whose clock every frame's measured cost drives (--server-ms models the warp server "
        "instead, labelled). --seed-table sets this machine's latencies beside the seeds' Table 2; --variants plots "
        "image error against latency saved for each warp variant; --photon-residual films each predictor aimed at "
        "the photons and at scan-out. The grid is a spec file "
        "(BenchGrid's settings, each with its default: --spec FILE.toml sets any of them), the grid's options override it; "
        "its latency films are written beside the runs as films.toml, which `rig sweep` films again. The default grid "
        "takes several minutes, --seed-table up to an hour; --quick runs a tiny one of each.",
    )
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--seed-table", action="store_true", help="the seeds' Table 2 beside this machine's (see rig.bench.seed_table)")
    mode.add_argument("--variants", action="store_true", help="image error against latency saved for each warp variant and scene")
    mode.add_argument("--photon-residual", action="store_true", help="latency left by each predictor aimed at the photons and at scan-out")
    parser.add_argument("--json", type=outputs.json_file, metavar="OUT.json", help="write the rows as a JSON list")
    parser.add_argument("--csv", type=outputs.csv_file, metavar="OUT.csv", help="write the rows as CSV")
    parser.add_argument("--plot", type=outputs.plot_file, metavar="OUT.png", help="plot the run (latency against N, error against latency saved, ...)")
    grid = parser.add_mutually_exclusive_group()
    grid.add_argument("--spec", type=Path, metavar="SPEC.toml",
                      help="the grid, as a TOML file of rig.bench.renderers.BenchGrid's settings (default: BenchGrid's defaults)")  # fmt: skip
    grid.add_argument("--quick", action="store_true", help=f"a tiny run (a smoke test, seconds not minutes; {renderers.QUICK_SPEC.name})")
    parser.add_argument("--triangles", type=_int_list, metavar="N,N,...", help="load sizes (default 10000,100000,1000000,5000000; --variants 10000,200000)")
    parser.add_argument("--resolutions", type=_resolution_list, metavar="WxH,...", help="display sizes; the first is the latency runs' (default 320x240,640x480,1280x720)")
    parser.add_argument("--ratios", type=_ratio_list, metavar="R,R,...", help="display frames per client frame (default 1,5,10)")
    parser.add_argument("--warp", metavar="SPEC", help="the warp renderer and its options, e.g. warp:recon=grid,views=2 (default: warp)")
    parser.add_argument("--load", choices=LOAD_SHAPES, help="--variants, --seed-table: what the load's triangles make, a soup of small random ones (the stress case) or a few tessellated solid objects (default: soup)")
    parser.add_argument("--variant", action="append", metavar="SPEC", help="a warp variant for --variants; repeat for several (default: the seeds' features one by one)")
    parser.add_argument("--predictor", help="the predictor of every latency run, both renderers alike (default: the spec's, hold, as the seeds' Table 2)")
    parser.add_argument("--direct-predictor", metavar="NAME", help="a different predictor for the direct renderer in the grid's latency runs")
    parser.add_argument("--residual-predictor", action="append", metavar="NAME", help="a predictor for --photon-residual; repeat for several (default: adaptive, kalman-ca, kalman-cv, desp, slerp, hold)")
    parser.add_argument("--server-ms", type=options.positive_float, metavar="MS", help="model the warp server's cost at MS per composed image, a GPU-like figure, labelled modelled (default: measured here; --photon-residual: 2)")
    parser.add_argument("--max-frame-s", type=options.positive_float, default=seed_table.SeedTableSpec().max_frame_s, help="--seed-table: the largest direct frame, in seconds, a scene may take (default: %(default)s)")
    parser.add_argument("--max-triangles", type=options.positive_int, metavar="N", help="--seed-table: the largest load (default: 20000000, 720 MB and the GL driver's copy)")
    parser.add_argument("--runs", type=outputs.output_folder, metavar="DIR",
                        help="keep the latency runs' videos here, and the grid's films.toml and summary (default: a temporary folder)")  # fmt: skip
    options.add_executor_options(parser, "the latency films")
    parser.set_defaults(func=_run)
