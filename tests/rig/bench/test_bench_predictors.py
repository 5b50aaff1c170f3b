"""`rig bench predictors` on a tiny trace: table, JSON and plot."""

import argparse
import json

import numpy as np

from predictors import Trace, write_trace
from predictors import quaternion as quat
from rig.bench import predictors as bench
from rig.commands import bench as bench_command


def parser() -> argparse.ArgumentParser:
    root = argparse.ArgumentParser(prog="rig")
    bench_command.add_parser(root.add_subparsers(dest="command", required=True))
    return root


def test_bench_on_a_tiny_trace_prints_the_table_and_writes_json_and_plot(tmp_path, capsys):
    t = np.arange(120) / 60.0
    trace = Trace.from_samples("tiny", t, np.outer(t, [0.2, 0.0, 0.0]), quat.from_rotation_vector(np.outer(t, [0, 1.0, 0])))
    write_trace(tmp_path / "tiny.csv", trace)
    args = parser().parse_args([
        "bench", "predictors", "--trace", str(tmp_path / "tiny.csv"), "--predictor", "slerp", "--predictor", "kalman-cv",
        "--predictor", "desp:position_alpha=0.4", "--horizons-ms", "0,50", "--timing-repeats", "1",
        "--json", str(tmp_path / "out.json"), "--plot", str(tmp_path / "out.png"),
    ])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "| tiny | kalman-cv |" in out and "kalman-cv / desp cost on tiny:" in out
    record = json.loads((tmp_path / "out.json").read_text())
    assert [r["predictor"] for r in record["results"]] == ["slerp", "kalman-cv", "desp"]
    slerp = record["results"][0]["scores"][1]
    assert slerp["horizon_ms"] == 50.0 and slerp["position_p95_mm"] < 1e-6
    assert record["results"][2]["params"] == {"position_alpha": 0.4}
    assert (tmp_path / "out.png").stat().st_size > 10_000


def test_the_default_traces_are_pendulum_synthetic_head_and_real():
    traces = bench.default_traces(2.0, seed=0)
    assert [t.name for t in traces] == ["pendulum", "synthetic-head", "hmd_orientation_user1"]
    assert np.all(traces[0].t_arrival > traces[0].t)  # transport delay
