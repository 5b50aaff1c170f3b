"""`rig tune` on tiny traces: fits, reports training and validation errors against the defaults and
constant velocity, writes only what beats the defaults on validation, and refuses traces out of
time order unless asked to repair them."""

import json
import math

import numpy as np
import pytest

from predictors import Trace, make, read_params, write_trace
from predictors import quaternion as quat
from predictors.synthetic import head_motion
from rig.cli import main
from rig.commands import options


@pytest.fixture(scope="module")
def head_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("traces") / "head.csv"
    write_trace(path, head_motion(6.0, 60.0, seed=2).with_noise(0.001, math.radians(0.2), seed=2))
    return path


@pytest.mark.slow
def test_tune_writes_parameters_that_simulate_and_make_accept(head_file, tmp_path, capsys):
    out = tmp_path / "tuned.json"
    assert main(["tune", "kalman-cv", "--trace", str(head_file), "--horizon-ms", "50", "--max-iterations", "10", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "training (deg, mm)" in printed and "validation (deg, mm)" in printed
    for label in ("kalman-cv tuned", "kalman-cv defaults", "slerp (constant velocity)", "default (rls)"):
        assert label in printed
    assert f"wrote {out}" in printed
    name, params = read_params(out)
    assert name == "kalman-cv" and set(params) == {"acceleration_noise", "angular_acceleration_noise", "angular_velocity_damping"}
    assert options.predictor_spec(f"kalman-cv:{out}") == ("kalman-cv", params)
    record = json.loads(out.read_text())
    assert record["validation_loss_over_defaults"] <= 1.0 and set(record["errors"]) == {"training", "validation"}
    make(name, **params)


@pytest.mark.slow
def test_parameters_that_lose_on_validation_are_not_written_unless_forced(tmp_path, capsys):
    """Trained on a still head (noise only) the smoothing is all-out; the head then turns."""
    t = np.arange(600) / 60.0
    angle = np.where(t < 6.0, 0.0, 2.0 * (t - 6.0))
    rng = np.random.default_rng(3)
    orientation = quat.multiply(quat.from_rotation_vector(np.outer(angle, [0.0, 1.0, 0.0])),
                                quat.from_rotation_vector(rng.normal(0.0, math.radians(0.3), (t.size, 3))))
    write_trace(tmp_path / "still-then-turn.csv", Trace.from_samples("still-then-turn", t, np.zeros((t.size, 3)), orientation))
    out = tmp_path / "tuned.json"
    command = ["tune", "desp", "--trace", str(tmp_path / "still-then-turn.csv"), "--horizon-ms", "50", "--max-iterations", "10",
               "--out", str(out), "--json"]
    assert main(command) == 1
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert report["written"] is False and report["validation_loss_over_defaults"] > 1.0 and not out.exists()
    assert "not written" in captured.err and "--force" in captured.err
    assert main([*command, "--force"]) == 0
    assert json.loads(capsys.readouterr().out)["written"] is True and out.exists()


@pytest.mark.parametrize(("times", "fault"), [([0.0, 0.02, 0.01, 0.03], "earlier"), ([0.0, 0.01, 0.01, 0.02], "same time")])
def test_traces_out_of_time_order_are_refused_with_where(tmp_path, capsys, times, fault):
    motion = head_motion(3.0, 60.0, seed=4)
    t = motion.t.copy()
    t[: len(times)] = times
    t[len(times):] += 0.05
    write_trace(tmp_path / "bad.csv", Trace.from_samples("bad", t, motion.position, motion.orientation))
    assert main(["tune", "desp", "--trace", str(tmp_path / "bad.csv"), "--horizon-ms", "20", "--out", str(tmp_path / "p.json")]) == 2
    error = capsys.readouterr().err
    assert "not in time order" in error and fault in error and "--repair" in error and error.count("\n") == 1


@pytest.mark.slow
def test_repair_sorts_the_trace_and_says_so(tmp_path, capsys):
    motion = head_motion(4.0, 60.0, seed=5).with_noise(0.001, math.radians(0.2), seed=5)
    order = np.arange(len(motion))
    order[[10, 11]] = order[[11, 10]]
    t = motion.t[order]
    t[40] = t[39]
    write_trace(tmp_path / "swapped.csv", Trace.from_samples("swapped", t, motion.position[order], motion.orientation[order]))
    out = tmp_path / "p.json"
    code = main(["tune", "desp", "--trace", str(tmp_path / "swapped.csv"), "--horizon-ms", "20", "--max-iterations", "3",
                 "--out", str(out), "--repair", "--force", "--json"])  # fmt: skip
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["repaired"] == [
        "swapped: 1 sample(s) earlier than the one before and 1 at the same time as the one before; "
        "sorted by time, 1 repeated time(s) dropped"
    ]
    assert report["samples"]["training"] + report["samples"]["validation"] == len(motion) - 1
