"""`rig bench renderers --quick`: every row and figure is there, and the numbers are sane."""

from __future__ import annotations

import argparse
import csv
import json

import pytest

from rig.commands import bench
from rig.bench.renderers import QUICK_GRID, ROW_FIELDS


def bench_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rig")
    bench.add_parser(parser.add_subparsers(dest="command", required=True))
    return parser


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("bench")
    args = bench_parser().parse_args(
        ["bench", "renderers", "--quick", "--json", str(out / "rows.json"), "--csv", str(out / "rows.csv"), "--plot", str(out / "bench.png")]
    )
    assert args.func(args) == 0
    return out, json.loads((out / "rows.json").read_text())


def test_there_is_a_row_per_renderer_size_resolution_and_ratio(quick_run):
    _, rows = quick_run
    keys = {(r["renderer"], r["triangles"], r["width"], r["height"], r["rate_ratio"]) for r in rows}
    (width, height), = QUICK_GRID.resolutions
    expected = {("direct", n, width, height, None) for n in QUICK_GRID.triangles}
    expected |= {("warp", n, width, height, ratio) for n in QUICK_GRID.triangles for ratio in QUICK_GRID.ratios}
    assert keys == expected and len(rows) == len(expected)
    assert all(set(r) == set(ROW_FIELDS) for r in rows)


def test_the_figures_are_filled_in_where_they_apply(quick_run):
    _, rows = quick_run
    for r in rows:
        assert r["frame_ms_median"] > 0 and r["frame_ms_p95"] >= r["frame_ms_median"] and r["frame_cpu_ms_median"] > 0
        if r["triangles"] in QUICK_GRID.latency_triangles:
            assert r["latency_true_ms"] > 0 and "cost measured, then modelled" in r["latency_note"]
            assert abs(r["latency_measured_ms"] - r["latency_true_ms"]) < 1.5
        else:
            assert r["latency_measured_ms"] is None and r["latency_note"] is None
        if r["renderer"] == "warp":
            assert r["client_ms_median"] > 0
            assert 0 <= r["lab_error_pct"] < 5 and 0 <= r["hole_pct"] < 5 and r["psnr_db"] > 20
        else:
            assert r["client_ms_median"] is None and r["lab_error_pct"] is None and r["hole_pct"] is None


def test_warping_further_ahead_makes_more_holes(quick_run):
    _, rows = quick_run
    for n in QUICK_GRID.triangles:
        by_ratio = {r["rate_ratio"]: r for r in rows if r["renderer"] == "warp" and r["triangles"] == n}
        low, high = min(by_ratio), max(by_ratio)
        assert by_ratio[high]["hole_pct"] > by_ratio[low]["hole_pct"]


def test_csv_and_plot_are_written(quick_run):
    out, rows = quick_run
    with (out / "rows.csv").open() as stream:
        assert len(list(csv.DictReader(stream))) == len(rows)
    assert (out / "bench.png").stat().st_size > 20_000


def test_bad_grid_options_are_rejected(capsys: pytest.CaptureFixture[str]):
    for bad in (["--resolutions", "640by480"], ["--ratios", "0"], ["--triangles", "ten"]):
        with pytest.raises(SystemExit):
            bench_parser().parse_args(["bench", "renderers", *bad])
    assert "error" in capsys.readouterr().err
