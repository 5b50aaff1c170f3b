"""`rig plan`: its recommendation, filmed by `rig simulate` with the options it prints and measured
by `rig analyse` as it says (or with the bench profile it wrote), reaches the accuracy it promised."""

import json
import shlex
from pathlib import Path

import pytest

from rig.cli import main
from rig.errors import ConfigError
from rig.service import PlanRequest
from rig.service.plan import Setting, film_needed


@pytest.mark.slow
def test_the_recommendation_filmed_again_reaches_the_promised_accuracy(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    profile = tmp_path / "bench.toml"
    argv = ["plan", "--display-hz", "72", "--camera-fps", "60,144", "--period-s", "0.8", "--accuracy-ms", "1", "--json", "--bench", str(profile)]
    assert main(argv) == 0
    plan = json.loads(capsys.readouterr().out)
    best = plan["recommended"]
    assert best is not None and best["expected_half_width_ms"] <= 1.0
    assert {s["camera_fps"] for s in plan["settings"]} == {60.0, 144.0}
    simulate_line, analyse_line = plan["commands"]
    out = tmp_path / "plan"
    simulate_argv = shlex.split(simulate_line)[1:]
    simulate_argv[simulate_argv.index("--out") + 1] = str(out)
    assert main(simulate_argv) == 0
    analyse_argv = shlex.split(analyse_line)[1:]
    analyse_argv[1] = str(out / "video.avi")
    capsys.readouterr()
    assert main([*analyse_argv, "--json"]) in (0, 3)
    result = json.loads(capsys.readouterr().out)
    truth = json.loads((out / "truth.json").read_text())["latency_ms"]
    low, high = result["ci95_ms"]
    assert (high - low) / 2 <= 1.0
    assert low <= truth <= high
    # The bench profile the plan wrote gives the same answer as the options it printed.
    assert main(["analyse", str(out / "video.avi"), "--bench", str(profile), "--json"]) in (0, 3)
    hinted = json.loads(capsys.readouterr().out)
    assert (hinted["latency_ms"], hinted["ci95_ms"]) == (result["latency_ms"], result["ci95_ms"])
    assert {record["name"]: record["verdict"] for record in hinted["hints"]}["fps"] == "agrees"


def test_the_film_needed_grows_as_the_accuracy_tightens() -> None:
    request = PlanRequest(display_hz=60.0, camera_fps=(240.0,), accuracy_ms=0.2)
    setting = Setting(240.0, 1.0, 4, 0.0, 4.0, 0.3, 0.05, 0.01, None, None)
    film = film_needed(setting, request)
    assert film is not None and setting.half_width_at(film) <= 0.2 < setting.half_width_at(film - 1.0)
    assert film_needed(Setting(240.0, 0.5, 4, 1.04, 4.0, 0.3, 0.25, 0.2, None, None), request) is None


@pytest.mark.parametrize(
    "bad", [dict(camera_fps=(5.0,)), dict(camera_fps=()), dict(exposures=(1.5,)), dict(accuracy_ms=0.0), dict(display_hz=0.0)]
)
def test_a_plan_request_is_checked_where_it_enters(bad: dict) -> None:
    with pytest.raises(ConfigError):
        PlanRequest(**{"display_hz": 60.0, "camera_fps": (120.0,), **bad})


def test_plan_options_are_one_line_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", "--display-hz", "60", "--camera-fps", "120", "--exposures", "2"]) == 2
    assert "exposures" in capsys.readouterr().err
