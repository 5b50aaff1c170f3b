"""The warp renderer in a simulated run: a new image every refresh, latency independent of the
client's cost, the server's modelled cost on record, and `rig demo --compare`."""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np
import pytest

from rig.commands import demo
from rig.service import SimulationConfig, simulate
from rig.session import DEFAULT_SERVER_MS
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig

SMALL_CAMERA = CameraConfig(fps=120.0, width=320, height=240, subsamples=4)
REFRESH_MS = 1e3 / 60.0


def warp_run(out: Path, app_frame_ms: float, warp_ms: float | None = DEFAULT_SERVER_MS):
    config = SimulationConfig(
        duration_s=1.5,
        camera=SMALL_CAMERA,
        display=DisplayConfig(width=160, height=120),
        renderer="warp",
        predictor="hold",  # no prediction: the costs show in the latency as they are
        scene_triangles=2_000,
        app_frame_ms=app_frame_ms,
        warp_ms=warp_ms,
    )
    return simulate(config, out)


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory):
    """Client frames of 20 and 200 ms with the default server cost, and 20 ms with a 10 ms server."""
    out = tmp_path_factory.mktemp("warp-runs")
    return {
        "cheap": warp_run(out / "cheap", 20.0),
        "dear": warp_run(out / "dear", 200.0),
        "slow-server": warp_run(out / "slow-server", 20.0, warp_ms=10.0),
    }


def rows(path: Path) -> list[dict[str, str]]:
    with path.open() as stream:
        return list(csv.DictReader(stream))


def test_the_server_shows_a_new_image_every_refresh_and_its_cost_is_on_record(runs):
    run = runs["dear"]
    shown = rows(run.out_dir / "display_frames.csv")
    assert [int(r["image"]) for r in shown] == [int(r["refresh"]) for r in shown]
    apps = rows(run.out_dir / "app_frames.csv")
    assert {r["cost_source"] for r in apps} == {"modelled"}
    starts = np.array([float(r["t_start"]) for r in apps])
    np.testing.assert_allclose(np.diff(starts), 0.2, rtol=1e-9)  # the client runs back to back
    assert run.truth.display_frame_cost == {"ms": DEFAULT_SERVER_MS, "source": "modelled"}
    # sensor to vertical blank: the transport delay and the server's modelled cost, plus the wait for
    # a tracker sample (one interval, two when jitter makes one late), never the client's 200 ms
    delays = np.array([float(r["t_vblank"]) - float(r["t_sensor_newest"]) for r in shown]) * 1e3
    assert delays.min() > 4.0 + DEFAULT_SERVER_MS - 1.0
    assert delays.max() < 4.0 + DEFAULT_SERVER_MS + 2e3 / 120.0 + 1.0


def test_the_latency_does_not_depend_on_the_clients_cost(runs):
    cheap, dear = runs["cheap"].truth, runs["dear"].truth
    assert dear.latency_ms == pytest.approx(cheap.latency_ms, abs=REFRESH_MS / 4)
    assert dear.display_frame_delay_ms.mean == pytest.approx(cheap.display_frame_delay_ms.mean, abs=1.0)


def test_a_modelled_warp_cost_delays_the_servers_sample(runs):
    quick, slow = runs["cheap"].truth, runs["slow-server"].truth
    assert slow.display_frame_cost == {"ms": 10.0, "source": "modelled"}
    assert slow.latency_ms - quick.latency_ms == pytest.approx(10.0 - DEFAULT_SERVER_MS, abs=1.5)


def test_demo_compare_prints_both_latencies_and_the_warp_is_faster(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    parser = argparse.ArgumentParser()
    demo.add_parser(parser.add_subparsers())
    args = parser.parse_args(
        ["demo", "--compare", "--out", str(tmp_path), "--duration", "2.5", "--camera-fps", "120", "--scene-triangles", "2000", "--app-frame-ms", "60",
         "--predictor", "hold", "--json"]  # fmt: skip
    )
    assert args.func(args) == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report) == {"direct", "warp"}
    for name in ("direct", "warp"):
        assert report[name]["agrees"]
        assert (tmp_path / name / "truth.json").exists()
    assert report["direct"]["latency_measured_ms"] > report["warp"]["latency_measured_ms"] + 50.0


def test_a_measured_server_cost_drives_the_clock_and_its_misses_are_on_record(tmp_path: Path):
    """Whatever this machine's GL costs: each composed image is charged what it took, appears no
    earlier than the refresh it was aimed at (its id), and a refresh without a new image is logged
    as missed, in display_frames.csv and in the truth."""
    run = warp_run(tmp_path, 20.0, warp_ms=None)
    truth = run.truth
    assert truth.display_frame_cost["source"] == "measured" and truth.display_frame_cost["median_ms"] > 0.0
    assert truth.app_frame_cost == {"ms": 20.0, "source": "modelled"}
    shown = rows(run.out_dir / "display_frames.csv")
    assert {r["cost_source"] for r in shown} == {"measured"}
    for before, row in zip(shown, shown[1:]):
        assert (row["missed"] == "1") == (row["image"] == before["image"])
    fresh = [r for r in shown if r["missed"] == "0"]
    assert all(int(r["refresh"]) >= int(r["image"]) for r in fresh)
    costs_ms = {int(r["image"]): float(r["image_cost_s"]) * 1e3 for r in fresh}
    assert 0.0 < min(costs_ms.values()) and max(costs_ms.values()) <= truth.display_frame_cost["max_ms"] + 1e-9
    if truth.display_frame_cost["median_ms"] > REFRESH_MS:
        assert truth.refreshes.missed > truth.refreshes.shown / 3  # a server slower than a refresh cannot make them all
    summary = run.summary()
    assert summary["refreshes"] == {"shown": truth.refreshes.shown, "missed": truth.refreshes.missed}
    assert summary["display_frame_cost"] == truth.display_frame_cost and "measured, median" in run.cost_line()
