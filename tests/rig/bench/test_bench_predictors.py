"""`rig bench predictors` on tiny traces: tables, ratios to constant velocity, leave-one-out, JSON and plot."""

import json
import math

import numpy as np
import pytest

from predictors import Trace, write_trace
from predictors import quaternion as quat
from predictors.synthetic import head_motion
from rig.bench import predictor_scores
from rig.bench import predictors as bench
from rig.cli import build_parser

RIG_BENCH = build_parser(["bench"])
"""`rig`'s command line with its bench command."""


def test_bench_on_a_tiny_trace_prints_the_tables_and_writes_json_and_plot(tmp_path, capsys):
    t = np.arange(120) / 60.0
    trace = Trace.from_samples("tiny", t, np.outer(t, [0.2, 0.0, 0.0]), quat.from_rotation_vector(np.outer(t, [0, 1.0, 0])))
    write_trace(tmp_path / "tiny.csv", trace)
    args = RIG_BENCH.parse_args([
        "bench", "predictors", "--trace", str(tmp_path / "tiny.csv"), "--predictor", "slerp", "--predictor", "kalman-cv",
        "--predictor", "desp:position_alpha=0.4", "--horizons-ms", "0,50", "--timing-repeats", "1",
        "--json", str(tmp_path / "out.json"), "--plot", str(tmp_path / "out.png"),
    ])
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "| tiny | kalman-cv |" in out and "kalman-cv / desp cost on tiny:" in out
    assert "angular RMS error / constant velocity (slerp) at 50 ms:" in out and "| slerp | 1.000 | 1.000 | 1.000 |" in out
    record = json.loads((tmp_path / "out.json").read_text())
    assert [r["predictor"] for r in record["results"]] == ["slerp", "kalman-cv", "desp"]
    slerp = record["results"][0]["scores"][1]
    assert slerp["horizon_ms"] == 50.0 and slerp["position_p95_mm"] < 1e-6
    assert record["results"][2]["params"] == {"position_alpha": 0.4}
    assert [r["predictor"] for r in record["ratios"]] == ["slerp", "kalman-cv", "desp:position_alpha=0.4"]
    assert record["baseline"] == "slerp" and record["leave_one_out"] == []
    assert (tmp_path / "out.png").stat().st_size > 10_000


def test_constant_velocity_is_always_run_as_the_baseline(tmp_path, capsys):
    write_trace(tmp_path / "head.csv", head_motion(2.0, 60.0, seed=1))
    args = RIG_BENCH.parse_args(["bench", "predictors", "--trace", str(tmp_path / "head.csv"), "--predictor", "hold",
                                "--horizons-ms", "20", "--plot-horizon-ms", "20", "--timing-repeats", "0"])  # fmt: skip
    assert args.func(args) == 0
    assert "| head | slerp |" in capsys.readouterr().out


def test_ratios_are_errors_over_constant_velocity_and_their_geometric_mean():
    traces = [head_motion(3.0, 60.0, seed=s).with_noise(0.001, math.radians(0.2), seed=s) for s in (1, 2)]
    traces = [Trace.from_samples(f"head{k}", tr.t, tr.position, tr.orientation) for k, tr in enumerate(traces)]
    results = bench.evaluate_all(traces, [("slerp", {}), ("hold", {})], [20.0, 50.0], timing_repeats=1)
    record = predictor_scores.ratios_record(predictor_scores.scores_of(results, [20.0, 50.0]))
    ratios = {entry["predictor"]: entry for entry in record}
    by = {(r.trace, r.predictor): r for r in results}
    for trace in ("head0", "head1"):
        expected = by[(trace, "hold")].at(50.0).angular_rms_deg / by[(trace, "slerp")].at(50.0).angular_rms_deg
        assert ratios["hold"]["angular"][trace]["50"] == pytest.approx(expected)
        assert ratios["slerp"]["angular"][trace]["50"] == 1.0
        assert ratios["hold"]["us_per_update"][trace] == by[(trace, "hold")].us_per_update
    hold = ratios["hold"]["angular"]
    geometric_mean = math.sqrt(hold["head0"]["50"] * hold["head1"]["50"])
    assert ratios["hold"]["geometric_mean"]["angular"]["50"] == pytest.approx(geometric_mean)
    assert ratios["hold"]["worst"]["angular"]["50"] == max(hold["head0"]["50"], hold["head1"]["50"])


def test_a_trace_without_position_has_no_position_ratio():
    trace = head_motion(2.0, 60.0, seed=3)
    still = Trace.from_samples("still", trace.t, np.zeros((len(trace), 3)), trace.orientation)
    results = bench.evaluate_all([still], [("slerp", {}), ("adaptive", {})], [50.0], timing_repeats=0)
    entry = predictor_scores.ratios_record(predictor_scores.scores_of(results, [50.0]))[1]
    assert entry["position"]["still"]["50"] is None and entry["geometric_mean"]["position"]["50"] is None
    assert entry["angular"]["still"]["50"] > 0.0


@pytest.mark.slow
def test_leave_one_out_tunes_on_the_others_and_scores_the_one_held_out(tmp_path, capsys):
    for seed in (4, 5):
        write_trace(tmp_path / f"head{seed}.csv", head_motion(4.0, 60.0, seed=seed).with_noise(0.001, math.radians(0.3), seed=seed))
    args = RIG_BENCH.parse_args([
        "bench", "predictors", "--trace", str(tmp_path / "head4.csv"), "--trace", str(tmp_path / "head5.csv"),
        "--predictor", "desp", "--horizons-ms", "50", "--timing-repeats", "0", "--leave-one-out", "desp",
        "--tune-iterations", "3", "--json", str(tmp_path / "out.json"),
    ])
    assert args.func(args) == 0
    assert "leave one trace out: tuned at 50 ms on the others" in capsys.readouterr().out
    held = json.loads((tmp_path / "out.json").read_text())["leave_one_out"]
    assert [h["trace"] for h in held] == ["head4", "head5"]
    for h in held:
        assert 0.0 < h["params"]["orientation_alpha"] < 1.0 and h["angular"] > 0.0 and h["defaults_angular"] > 0.0


def test_leave_one_out_needs_a_tunable_predictor_and_two_traces(tmp_path):
    with pytest.raises(SystemExit):
        RIG_BENCH.parse_args(["bench", "predictors", "--leave-one-out", "adaptive"])
    write_trace(tmp_path / "head.csv", head_motion(2.0, 60.0, seed=1))
    args = RIG_BENCH.parse_args(["bench", "predictors", "--trace", str(tmp_path / "head.csv"), "--predictor", "desp",
                                "--horizons-ms", "50", "--timing-repeats", "0", "--leave-one-out", "desp"])  # fmt: skip
    with pytest.raises(Exception, match="at least two traces"):
        args.func(args)


def test_the_default_traces_are_pendulum_synthetic_head_and_both_recordings():
    traces = bench.default_traces(2.0, seed=0)
    assert [t.name for t in traces] == ["pendulum", "synthetic-head", "hmd_orientation_user1", "quest_pro_robot_traj2"]
    assert np.all(traces[0].t_arrival > traces[0].t)  # transport delay
    assert np.ptp(traces[3].position, axis=0).max() > 0.1  # the 6-DoF recording moves


def test_stress_runs_the_stress_streams(tmp_path, capsys):
    args = RIG_BENCH.parse_args(["bench", "predictors", "--stress", "--duration", "1", "--predictor", "hold",
                                "--horizons-ms", "20", "--plot-horizon-ms", "20", "--timing-repeats", "0"])  # fmt: skip
    assert args.func(args) == 0
    out = capsys.readouterr().out
    assert "| head-1000Hz-noisy | hold |" in out and "| stops-60Hz | slerp |" in out


def test_a_predictor_that_failed_on_one_trace_has_failed_there_and_its_mean_says_over_how_many():
    traces = [head_motion(2.0, 60.0, seed=seed).with_noise(0.001, math.radians(0.3), seed=seed) for seed in (1, 2)]
    traces = [Trace.from_samples(f"head{k}", t.t, t.position, t.orientation) for k, t in enumerate(traces)]
    results = predictor_scores.evaluate_all(traces, [("slerp", {}), ("hold", {})], [50.0], 0)
    scores = predictor_scores.scores_of([r for r in results if (r.predictor, r.trace) != ("hold", "head1")], [50.0])
    rows = {row.split(" | ")[0].strip("| "): row for row in bench.ratio_table(scores, "angular", [50.0]).splitlines()[2:]}
    hold_on_head0 = scores.ratio("hold", "head0", "angular", 50.0)
    assert rows["hold"].startswith(f"| hold | {hold_on_head0:.3f} | failed | {hold_on_head0:.3f} (1 of 2 traces) | ")
    assert rows["slerp"].startswith("| slerp | 1.000 | 1.000 | 1.000 | 1.000 | ")
