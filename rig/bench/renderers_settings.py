"""`rig bench renderers`: time the direct renderer and the warp renderer's client and server for
load sizes and display resolutions, measure the image error of warped frames against direct
renders, and the latency `rig analyse` finds in simulated videos whose clock every frame's measured
cost drives (--server-ms models the warp server instead, labelled). --seed-table sets this
machine's latencies beside Smit et al.'s (2010, Table 2); --variants plots image error against latency saved
for each warp variant; --photon-residual films each predictor aimed at the photons and at
scan-out. The grid is a spec file, the grid's options override it; its latency films are written
beside the runs as films.toml, which `rig sweep` films again. The default grid takes several
minutes, --seed-table up to an hour; --quick runs a tiny one of each.

Declared here, with its modes, without the benches' libraries, for the command line;
`rig.bench.renderers`, `rig.bench.seed_table`, `rig.bench.warp_variants` and
`rig.bench.photon_residual` run them.
"""

from __future__ import annotations

import argparse

from rig.bench.contract import Command, SpecFile, bench_in
from rig.bench.renderer_specs import QUICK_SPEC, BenchGrid, SeedTableSpec
from rig.commands import options
from rig.commands.declared_options import declared_type
from rig.sim.config import LOAD_SHAPES


def _int_list(text: str) -> tuple[int, ...]:
    return tuple(options.non_negative_int(part) for part in text.split(","))


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


def _renderers_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--triangles", type=_int_list, metavar="N,N,...", help="load sizes (default 10000,100000,1000000,5000000; --variants 10000,200000)")
    parser.add_argument("--resolutions", type=lambda text: tuple(map(_resolution, text.split(","))), metavar="WxH,...",
                        help="display sizes; the first is the latency runs' (default 320x240,640x480,1280x720)")  # fmt: skip
    parser.add_argument("--ratios", type=_ratio_list, metavar="R,R,...", help="display frames per client frame (default 1,5,10)")
    parser.add_argument("--warp", metavar="SPEC", help="the warp renderer and its options, e.g. warp:recon=grid,views=2 (default: warp)")
    parser.add_argument("--load", choices=LOAD_SHAPES, help="--variants, --seed-table: what the load's triangles make, a soup of small random ones (the stress case) or a few tessellated solid objects (default: soup)")
    parser.add_argument("--predictor", help="the predictor of every latency run, both renderers alike (default: the spec's, hold, as in Smit et al. 2010, Table 2)")
    parser.add_argument("--direct-predictor", metavar="NAME", help="a different predictor for the direct renderer in the grid's latency runs")
    parser.add_argument("--server-ms", type=declared_type(BenchGrid, "server_ms"), metavar="MS", help="model the warp server's cost at MS per composed image, a GPU-like figure, labelled modelled (default: measured here; --photon-residual: 2)")


def _seed_table_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--max-frame-s", type=declared_type(SeedTableSpec, "max_frame_s"), metavar="S",
                        help="--seed-table: the largest direct frame, in seconds, a scene may take (default: 60)")  # fmt: skip
    parser.add_argument("--max-triangles", type=declared_type(SeedTableSpec, "max_triangles"), metavar="N",
                        help="--seed-table: the largest load (default: 20000000, 720 MB and the GL driver's copy)")  # fmt: skip


def _variants_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--variant", action="append", metavar="SPEC",
                        help="a warp variant for --variants; repeat for several (default: each published warp feature in turn: reconstructions, two views, hole levels, low-pass fill, spin)")  # fmt: skip


def _residual_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--residual-predictor", action="append", metavar="NAME",
                        help="a predictor for --photon-residual; repeat for several (default: adaptive, kalman-ca, kalman-cv, desp, slerp, hold)")  # fmt: skip


SUBJECT = Command(
    name="renderers",
    help="frame cost, latency and image error of the direct and warp renderers against scene size",
    bench=bench_in("renderers"),
    options=_renderers_options,
    outputs={"json": "write the rows as a JSON list", "csv": "write the rows as CSV",
             "plot": "plot the run (latency against N, error against latency saved, ...)"},
    spec_file=SpecFile(None, QUICK_SPEC,
                       help="the grid, as a TOML file of rig.bench.renderers.BenchGrid's settings (default: BenchGrid's defaults)",
                       quick_help=f"a tiny run (a smoke test, seconds not minutes; {QUICK_SPEC.name})"),
    runs="keep the latency runs' videos here, and the grid's films.toml and summary (default: a temporary folder)",
    executor="the latency films",
)  # fmt: skip
MODES = (
    Command(name="seed-table", help="Smit et al.'s latencies (2010, Table 2) beside this machine's (see rig.bench.seed_table)",
            bench=bench_in("seed_table"), options=_seed_table_options),
    Command(name="variants", help="image error against latency saved for each warp variant and scene",
            bench=bench_in("warp_variants"), options=_variants_options),
    Command(name="photon-residual", help="latency left by each predictor aimed at the photons and at scan-out",
            bench=bench_in("photon_residual"), options=_residual_options),
)  # fmt: skip
"""--seed-table, --variants and --photon-residual: benches of their own on the grid's parts."""
