"""`rig bench renderers --quick` in each of its modes: every row and figure is there, and the numbers are sane."""

from __future__ import annotations

import argparse
import csv
import json
import re
import tomllib
from pathlib import Path

import pytest

from rig.bench import renderers_settings, seed_table
from rig.bench.renderer_latency import FILMS_SPEC, film_latency
from rig.bench.renderer_setup import scene_setup
from rig.bench.renderer_specs import QUICK_SPEC, BenchGrid, read_grid
from rig.bench.renderers import LATENCY_FIELDS, ROW_FIELDS
from rig.bench.seed_table import SEED_SOURCE, SEED_TABLE_2, crossover, seed_rows
from rig.cli import EXIT_USER_ERROR, build_parser, main
from rig.commands import bench
from rig.errors import ConfigError
from rig.service.sweep import read_sweep
from rig.sim.camera import CameraConfig

RIG_BENCH = build_parser(["bench"])
"""`rig`'s command line with its bench command."""

QUICK_GRID = read_grid(QUICK_SPEC)


def _grid(args: argparse.Namespace) -> BenchGrid:
    return bench.spec(renderers_settings.SUBJECT, args)


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("bench")
    args = RIG_BENCH.parse_args(
        ["bench", "renderers", "--quick", "--json", str(out / "rows.json"), "--csv", str(out / "rows.csv"), "--plot", str(out / "bench.png"),
         "--runs", str(out / "runs")]
    )  # fmt: skip
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
            assert r["latency_true_ms"] > 0 and r["latency_note"].startswith("costs: application frame measured")
            assert r["cost_source"] == "measured" and r["predictor"] == "hold" and 0 <= r["missed_pct"] <= 100
            assert abs(r["latency_measured_ms"] - r["latency_true_ms"]) < 1.5
        else:
            assert r["latency_measured_ms"] is None and r["latency_note"] is None
        if r["renderer"] == "warp":
            assert r["client_ms_median"] > 0 and r["spec"] == "warp" and r["primitives"] > 0
            assert 0 <= r["lab_error_pct"] < 5 and 0 <= r["hole_pct"] < 5 and r["psnr_db"] > 20
            assert 0.9 < r["ssim"] <= 1.0 and r["dssim"] == pytest.approx((1 - r["ssim"]) / 2)
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


def test_the_film_rows_are_the_sweeps_summary_rows(quick_run):
    out, rows = quick_run
    summary = json.loads((out / "runs" / "summary.json").read_text())
    assert not summary["partial"]
    swept = {(r["renderer"], int(r["triangles"])): r for r in summary["rows"]}
    assert set(swept) == {(renderer, n) for renderer in ("direct", "warp") for n in QUICK_GRID.latency_triangles}
    filmed = [r for r in rows if r["latency_measured_ms"] is not None]
    assert {(r["renderer"], r["triangles"]) for r in filmed} == set(swept)
    for r in filmed:
        row = swept[r["renderer"], r["triangles"]]
        assert (r["latency_measured_ms"], r["latency_true_ms"]) == (row["latency_ms"], row["truth_ms"])
        assert {name: r[name] for name in LATENCY_FIELDS} == {name: row["film"][name] for name in LATENCY_FIELDS}


def test_the_films_spec_sweeps_exactly_the_simulations_the_bench_filmed(quick_run, tmp_path):
    """What `rig sweep films.toml` would simulate, point by point, is what each film's truth.json
    says it was; re-filming is not compared, as its costs are measured again, so a loaded machine
    misses other refreshes."""
    out, _ = quick_run
    points = read_sweep(out / "runs" / FILMS_SPEC).points(tmp_path)
    filmed = json.loads((out / "runs" / "summary.json").read_text())["rows"]
    assert [point.labels for point in points] == [{"renderer": r["renderer"], "triangles": str(r["triangles"])} for r in filmed]
    for point, row in zip(points, filmed):
        truth = json.loads((Path(row["video"]).parent / "truth.json").read_text())
        assert json.loads(json.dumps(point.config.to_dict())) == truth["config"]
        assert point.simulated_rois


def test_a_spec_sets_the_settings_it_names_and_the_rest_keep_the_grids_defaults(tmp_path):
    spec = tmp_path / "grid.toml"
    spec.write_text("phases = 2\n[latency_camera]\nwidth = 320\n")
    assert read_grid(spec) == BenchGrid(phases=2, latency_camera=CameraConfig(width=320))
    assert read_grid(None) == BenchGrid()
    assert read_grid(QUICK_SPEC) == BenchGrid(
        triangles=(1_000, 8_000), resolutions=((160, 120),), ratios=(1, 3), phases=1, warp_rounds=3, direct_frames=3,
        direct_budget_s=1.0, latency_triangles=(1_000,), latency_camera=CameraConfig(width=320, height=240, subsamples=4),
        latency_duration_s=2.5, max_period_s=4.0,
    )  # fmt: skip


def test_the_specs_are_package_data():
    pyproject = tomllib.loads((Path(__file__).parents[3] / "pyproject.toml").read_text())
    patterns = pyproject["tool"]["setuptools"]["package-data"]["rig.bench"]
    shipped = {path for pattern in patterns for path in QUICK_SPEC.parents[1].glob(pattern)}
    assert QUICK_SPEC in shipped


def test_the_options_override_the_spec(tmp_path):
    spec = tmp_path / "grid.toml"
    spec.write_text('triangles = [500]\nwarp = "warp:recon=grid"\nserver_ms = 3.0\npredictor = "kalman-cv"\n')
    args = RIG_BENCH.parse_args(["bench", "renderers", "--spec", str(spec)])
    assert _grid(args) == BenchGrid(triangles=(500,), warp="warp:recon=grid", server_ms=3.0, predictor="kalman-cv")
    args = RIG_BENCH.parse_args(["bench", "renderers", "--spec", str(spec), "--triangles", "7,9", "--resolutions", "64x48",
                                      "--ratios", "2", "--warp", "warp", "--server-ms", "1", "--predictor", "hold", "--direct-predictor", "slerp"])  # fmt: skip
    assert _grid(args) == BenchGrid(triangles=(7, 9), resolutions=((64, 48),), ratios=(2,), server_ms=1.0, predictor="hold", direct_predictor="slerp")
    assert _grid(RIG_BENCH.parse_args(["bench", "renderers", "--quick", "--ratios", "4"])).ratios == (4,)


@pytest.mark.parametrize(
    "text, message",
    [
        ("triangle = [1000]\n", "unknown key triangle; BenchGrid takes triangles, "),
        ('triangles = "1000"\n', "triangles must be a list, each item a whole number, not '1000'"),
        ("triangles = [1000, 2.5]\n", "triangles\\[1\\] must be a whole number, not 2.5"),
        ('resolutions = ["320x240"]\n', "resolutions\\[0\\] must be a list of 2 items, each a whole number, not '320x240'"),
        ("resolutions = [[320, 240, 1]]\n", "resolutions\\[0\\] must be a list of 2 items"),
        ("phases = true\n", "phases must be a whole number, not True"),
        ("server_ms = \"2\"\n", "server_ms must be a number"),
        ("[latency_camera]\nwidht = 320\n", "unknown key latency_camera.widht; CameraConfig takes fps, "),
        ("latency_camera = 320\n", "latency_camera must be a table of CameraConfig settings"),
        ("ratios = [0]\n", "ratios must have each item a positive whole number from 1 to 100, got \\(0,\\)"),
        ("refresh_hz = 5000.0\n", "refresh_hz must be a positive number of Hz from 1 to 1000, got 5000.0"),
        ("ratios = []\n", "needs at least one"),
        ("triangles = [\n", "is not valid TOML"),
    ],
)
def test_a_bad_spec_is_one_line_and_exit_status_2(tmp_path, capsys, text, message):
    spec = tmp_path / "grid.toml"
    spec.write_text(text)
    assert main(["bench", "renderers", "--spec", str(spec), "--runs", str(tmp_path / "runs")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and str(spec) in err
    assert re.search(message, err), err
    assert not (tmp_path / "runs" / FILMS_SPEC).exists()


def test_bad_grid_options_are_rejected(capsys: pytest.CaptureFixture[str]):
    for bad in (["--resolutions", "640by480"], ["--ratios", "0"], ["--triangles", "ten"]):
        with pytest.raises(SystemExit):
            RIG_BENCH.parse_args(["bench", "renderers", *bad])
    assert "error" in capsys.readouterr().err


def test_a_grid_no_machine_could_finish_in_a_day_is_refused_with_its_estimate():
    assert read_grid(QUICK_SPEC).estimated_hours() < 1e-3
    with pytest.raises(ConfigError, match=r"this grid would take about 2\d\d hours at the least, more than the 24 hours"):
        BenchGrid(triangles=(100_000_000,), latency_duration_s=3600.0, refresh_hz=1000.0)


def run_quick(out, mode: str, *extra: str) -> tuple[list[dict], str]:
    args = RIG_BENCH.parse_args(["bench", "renderers", "--quick", mode, "--json", str(out / "rows.json"), "--plot", str(out / "plot.png"), *extra])
    assert args.func(args) == 0
    return json.loads((out / "rows.json").read_text())


@pytest.mark.slow
def test_the_seed_table_films_both_renderers_alike_and_sets_the_seeds_figures_beside(tmp_path, capsys):
    rows = run_quick(tmp_path, "--seed-table")
    ours = [r for r in rows if r["source"] == "this machine"]
    seed = [r for r in rows if r["source"] == SEED_SOURCE]
    assert {(r["renderer"], r["triangles"]) for r in ours} == {(renderer, n) for renderer in ("direct", "warp") for n in (1_000, 4_000)}
    for r in ours:
        assert {"renderer", "triangles", "width", "latency_measured_ms", "latency_sd_ms", "frame_ms_median", "cost_source"} <= set(r)
        assert r["cost_source"] == "measured" and r["predictor"] == "hold" and r["width"] == 160 and r["load"] == "soup"
        assert abs(r["latency_measured_ms"] - r["latency_true_ms"]) < 1.5 and r["latency_sd_ms"] >= 0
        assert r["latency_refreshes"] == pytest.approx(r["latency_measured_ms"] / (1e3 / 60))
    assert len(seed) == 2 * len(SEED_TABLE_2)
    printed = capsys.readouterr().out
    assert "crossover, seed: 2.15M triangles" in printed and "780.0 (14.2)" in printed
    assert (tmp_path / "plot.png").stat().st_size > 20_000


@pytest.mark.slow
def test_the_seed_table_probes_and_films_the_load_and_warp_it_is_given_and_says_so(tmp_path, capsys, monkeypatch):
    probed, filmed = [], []

    def probe(*args):
        probed.append(args[4])
        return scene_setup(*args)

    def film(run, *args):
        filmed.append((run.config.renderer, run.config.scene_load))
        return film_latency(run, *args)

    monkeypatch.setattr(seed_table, "scene_setup", probe)
    monkeypatch.setattr(seed_table, "film_latency", film)
    rows = run_quick(tmp_path, "--seed-table", "--load", "meshes", "--warp", "warp:recon=grid")
    assert probed == ["meshes", "meshes"] and filmed == [("direct", "meshes"), ("warp:recon=grid", "meshes")] * 2
    ours = [r for r in rows if r["source"] == "this machine"]
    assert {(r["renderer"], r["spec"], r["load"]) for r in ours} == {("direct", "direct", "meshes"), ("warp", "warp:recon=grid", "meshes")}
    assert all(r["latency_measured_ms"] > 0 and r["cost_source"] == "measured" for r in ours)
    assert "this machine (load meshes, warp warp:recon=grid;" in capsys.readouterr().out


@pytest.mark.slow
@pytest.mark.parametrize("load", ["soup", "meshes"])
def test_the_variants_plot_image_error_against_latency_saved(tmp_path, load):
    rows = run_quick(tmp_path, "--variants", "--load", load)
    assert [r["spec"] for r in rows] == ["warp", "warp:views=2,recon=grid,holes=1"]
    for r in rows:
        assert r["load"] == load
        assert r["latency_saved_ms"] == pytest.approx(r["direct_latency_ms"] - r["latency_measured_ms"])
        assert 0.9 < r["ssim"] <= 1.0 and r["primitives"] > 0 and r["server_ms_median"] > 0
    assert rows[1]["hole_pct"] <= rows[0]["hole_pct"]
    assert (tmp_path / "plot.png").stat().st_size > 20_000


@pytest.mark.slow
def test_aimed_at_the_photons_a_good_predictor_leaves_almost_no_latency(tmp_path, capsys):
    """With a GPU-like 2 ms server (modelled), kalman-cv aimed at the middle of each frame's photons
    brings the measured latency within 2 ms of zero; aimed at scan-out it leaves about half a refresh."""
    rows = run_quick(tmp_path, "--photon-residual", "--residual-predictor", "kalman-cv")
    by = {r["photon_target"]: r for r in rows}
    assert {r["cost_source"] for r in rows} == {"modelled"}
    assert abs(by["photons"]["latency_measured_ms"]) < 2.0
    assert by["scanout"]["latency_measured_ms"] - by["photons"]["latency_measured_ms"] == pytest.approx(1e3 / 60 / 2, abs=2.0)
    assert "best predictor kalman-cv" in capsys.readouterr().out


def test_the_crossover_is_interpolated_in_log_size_with_the_direct_frame_time_there():
    def row(renderer, n, latency, frame):
        return {"renderer": renderer, "triangles": n, "latency_measured_ms": latency, "frame_ms_median": frame, "refresh_ms": 10.0}

    rows = [row("direct", 1_000, 40.0, 2.0), row("warp", 1_000, 50.0, 5.0), row("direct", 4_000, 70.0, 8.0), row("warp", 4_000, 50.0, 5.0)]
    found = crossover(rows)
    assert found["triangles"] == pytest.approx(1_000 * 4 ** (1 / 3))
    assert found["direct_frame_ms"] == pytest.approx(2.0 * 4 ** (1 / 3)) and found["direct_frame_refreshes"] == pytest.approx(found["direct_frame_ms"] / 10)
    assert crossover(rows[:2]) is None
    seed = crossover(seed_rows())
    assert 2e6 < seed["triangles"] < 4e6 and 18.8 < seed["direct_frame_ms"] < 37.0
