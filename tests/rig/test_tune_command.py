"""`rig tune` on a tiny trace: fits, reports held-out error, writes a file `rig simulate` reads."""

import argparse
import math

import pytest

from predictors import make, read_params, write_trace
from predictors.synthetic import head_motion
from rig.commands import options, tune



def test_tune_writes_parameters_that_simulate_and_make_accept(tmp_path, capsys):
    write_trace(tmp_path / "head.csv", head_motion(6.0, 60.0, seed=2).with_noise(0.001, math.radians(0.2), seed=2))
    root = argparse.ArgumentParser(prog="rig")
    tune.add_parser(root.add_subparsers(dest="command", required=True))
    out = tmp_path / "tuned.json"
    args = root.parse_args(["tune", "desp", "--trace", str(tmp_path / "head.csv"), "--horizon-ms", "20",
                            "--max-iterations", "5", "--out", str(out)])
    assert args.func(args) == 0
    printed = capsys.readouterr().out
    assert "held-out RMS error at 20 ms" in printed and "slerp" in printed
    name, params = read_params(out)
    assert name == "desp" and 0.0 < params["position_alpha"] < 1.0 and 0.0 < params["orientation_alpha"] < 1.0
    assert options.predictor_spec(f"desp:{out}") == ("desp", params)
    make(name, **params)
