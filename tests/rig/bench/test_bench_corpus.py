"""`rig bench predictors --corpus`: scores by recording and group, cross-validation by person, scene
and device, recordings apart kept out of every group, JSON and plot."""

import json
import math

import numpy as np
import pytest

from predictors import Trace, write_trace
from predictors.synthetic import head_motion
from rig.errors import ConfigError
from tests.rig.bench.test_bench_predictors import RIG_BENCH


def corpus(folder):
    """Three people in a walking set (one in two scenes), one orientation-only user and a robot."""
    for k, name in enumerate(("walk_nyc_user1", "walk_hill_user1", "walk_hill_user2", "walk_nyc_user3")):
        trace = head_motion(3.0, 60.0, seed=k).with_noise(0.001, math.radians(0.3), seed=k)
        (folder / "walk").mkdir(exist_ok=True)
        write_trace(folder / "walk" / f"{name}.csv", trace)
    turning = head_motion(3.0, 60.0, seed=7)
    write_trace(folder / "hmd_user9.csv", Trace.from_samples("hmd_user9", turning.t, np.zeros((len(turning), 3)), turning.orientation))
    write_trace(folder / "arm_robot_1.csv", head_motion(3.0, 60.0, seed=8))


def run(tmp_path, *extra):
    corpus(tmp_path)
    args = RIG_BENCH.parse_args(["bench", "predictors", "--corpus", str(tmp_path), "--predictor", "hold", "--predictor", "kalman-cv",
                                "--horizons-ms", "20,50", "--timing-repeats", "1", *extra])  # fmt: skip
    return args.func(args)


def test_the_corpus_bench_scores_every_recording_and_each_person_held_out(tmp_path, capsys):
    assert run(tmp_path, "--cross-validate", "--json", str(tmp_path / "out.json"), "--plot", str(tmp_path / "out.png")) == 0
    out = capsys.readouterr().out
    assert "| arm_robot_1 | arm_robot_1 | arm_robot_1 (apart) | - |" in out
    assert "leave one person out" in out and "leave one scene out" in out and "leave one device out" in out
    assert "cross-validated (person): angular RMS / constant velocity at 20 / 50 ms:" in out
    record = json.loads((tmp_path / "out.json").read_text())
    folds = record["cross_validation"]["person"]["folds"]
    assert [f["group"] for f in folds] == ["hmd/user9", "walk/user1", "walk/user2", "walk/user3"]
    assert folds[1]["recordings"] == ["walk_hill_user1", "walk_nyc_user1"]
    assert [f["group"] for f in record["cross_validation"]["scene"]["folds"]] == ["hill", "nyc"]
    # Every held-out ratio is the chosen candidate's RMS error over constant velocity's on that group,
    # recomputed here from the raw results; the headline is their geometric mean.
    rms = {(r["predictor"], r["trace"]): {s["horizon_ms"]: s["angular_rms_deg"] for s in r["scores"]}
           for r in record["results"] if not r["params"]}  # fmt: skip
    logs = []
    for fold in folds:
        ratios = [rms[(fold["chosen"], name)][50.0] / rms[("slerp", name)][50.0] for name in fold["recordings"]]
        expected = math.exp(sum(map(math.log, ratios)) / len(ratios))
        assert fold["ratios"]["angular"]["50"] == pytest.approx(expected)
        logs.append(math.log(expected))
    assert record["cross_validation"]["person"]["geometric_mean"]["angular"]["50"] == pytest.approx(math.exp(sum(logs) / len(logs)))
    assert "arm_robot_1" not in [r for f in folds for r in f["recordings"]]
    assert record["candidates"]["kalman-cv"]["cost_over_kalman_cv"] == 1.0
    assert record["candidates"]["hold"]["recordings"]["hmd_user9"]["position"]["50"] is None
    assert (tmp_path / "out.png").stat().st_size > 10_000


def test_without_cross_validation_the_bench_reports_groups_only(tmp_path, capsys):
    assert run(tmp_path) == 0
    out = capsys.readouterr().out
    assert "by person (geometric mean over people" in out and "leave one" not in out


@pytest.mark.parametrize("extra, message", [
    (["--trace", "x.csv"], "--corpus runs on the corpus's recordings alone"),
    (["--stress"], "--corpus runs on the corpus's recordings alone"),
])  # fmt: skip
def test_the_corpus_bench_refuses_other_traces(tmp_path, extra, message):
    with pytest.raises(ConfigError, match=message):
        run(tmp_path, *extra)


@pytest.mark.parametrize("option", ["--cross-validate", "--headroom"])
def test_grouping_options_need_a_corpus(option):
    args = RIG_BENCH.parse_args(["bench", "predictors", option, "--predictor", "hold"])
    with pytest.raises(ConfigError, match="need --corpus DIR"):
        args.func(args)


def test_the_headroom_is_fitted_on_the_other_groups_and_reported_beside_the_default(tmp_path, capsys):
    assert run(tmp_path, "--predictor", "rls", "--headroom", "--json", str(tmp_path / "out.json"), "--plot", str(tmp_path / "out.png")) == 0
    out = capsys.readouterr().out
    assert "headroom, leave one person out: linear predictors on rls's features" in out
    assert ("| held out (person) | recordings | shared, fitted on the others | yaw/tilt, fitted on the others | per axis, fitted on the "
            "others | rls, on the stream |") in out
    headroom = json.loads((tmp_path / "out.json").read_text())["headroom"]
    assert set(headroom) == {"person", "scene", "device"}
    folds = headroom["person"]["folds"]
    assert [f["group"] for f in folds] == ["hmd/user9", "walk/user1", "walk/user2", "walk/user3"]
    for fit in ("shared", "yaw/tilt", "per axis"):
        ratios = [f["ratios"][fit]["50"] for f in folds]
        assert all(0.0 < r < 2.0 for r in ratios)
        assert headroom["person"]["geometric_mean"][fit]["50"] == pytest.approx(math.exp(sum(map(math.log, ratios)) / len(ratios)))
    assert (tmp_path / "out.png").stat().st_size > 10_000


def test_the_headroom_needs_a_horizon_ahead(tmp_path):
    with pytest.raises(ConfigError, match="--headroom fits predictions ahead"):
        run(tmp_path, "--headroom", "--horizons-ms", "0", "--plot-horizon-ms", "0")


def test_a_manifest_given_labels_the_corpus(tmp_path, capsys):
    corpus(tmp_path)
    rows = ["walk/walk_nyc_user1.csv,quest,ann,nyc,", "walk/walk_hill_user1.csv,quest,ann,hill,",
            "walk/walk_hill_user2.csv,quest,bob,hill,", "walk/walk_nyc_user3.csv,quest,cy,nyc,",
            "hmd_user9.csv,vive,dee,,", "arm_robot_1.csv,quest,robot,,yes"]  # fmt: skip
    manifest = tmp_path / "labels.csv"
    manifest.write_text("file,device,person,scene,apart\n" + "\n".join(rows) + "\n")
    args = RIG_BENCH.parse_args(["bench", "predictors", "--corpus", str(tmp_path), "--manifest", str(manifest), "--predictor", "hold",
                                "--horizons-ms", "50", "--timing-repeats", "0", "--cross-validate", "--json", str(tmp_path / "out.json")])  # fmt: skip
    assert args.func(args) == 0
    record = json.loads((tmp_path / "out.json").read_text())
    assert [f["group"] for f in record["cross_validation"]["person"]["folds"]] == ["dee", "ann", "bob", "cy"]
    assert [f["group"] for f in record["cross_validation"]["device"]["folds"]] == ["vive", "quest"]
