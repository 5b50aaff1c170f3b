"""The bench described once: a rolling-shutter film analysed with only `rig analyse --bench FILE`
finds the truth; a profile `rig plan --bench` writes gives the same answer as the options it
prints; the command line wins and the result says so; and each value the film contradicts is a
warning naming both, after which the value is not used as it stands."""

from __future__ import annotations

import json
import shlex
from pathlib import Path

import pytest

from rig.cli import EXIT_WARNINGS, main
from rig.service import SimulationConfig, simulate
from rig.service.plan import Plan, PlanRequest, Setting
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig

FPS, READOUT_MS, DISPLAY_HZ = 240.0, 3.5, 60.0
EXPOSURE_MS = 1e3 / FPS  # whole frames: four exposures tile a refresh, so the display's sampling adds no bias
TOLERANCE_MS = 0.3

PROFILE = f"""# our bench
[camera]
fps = {FPS}
fps_source = "the camera's menu"
exposure_ms = {EXPOSURE_MS:.4f}
readout_ms = {READOUT_MS}
readout_source = "rig calibrate-camera 2026-11-28 from flash.mp4"

[display]
refresh_hz = {DISPLAY_HZ}

[layout]
led_side = "left"
led_row = 0.33
sphere_row = 0.67
"""


@pytest.fixture(scope="module")
def film(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, float]:
    """A 240 fps camera whose rolling shutter reads a frame out in 3.5 ms, the LED 35 % of the frame
    above the sphere (1.2 ms between their rows), filming a 60 Hz display for 4 s: the video and the truth."""
    camera = CameraConfig(fps=FPS, width=320, height=240, subsamples=4, readout_s=READOUT_MS / 1e3)
    config = SimulationConfig(duration_s=4.0, camera=camera, layout="led-above", display=DisplayConfig(refresh_hz=DISPLAY_HZ))
    run = simulate(config, tmp_path_factory.mktemp("bench-film"))
    return run.video_path, run.truth.latency_ms


def _analysed(capsys: pytest.CaptureFixture[str], video: Path, profile: Path, *options: str) -> tuple[int, dict]:
    status = main(["analyse", str(video), "--bench", str(profile), *options, "--json"])
    return status, json.loads(capsys.readouterr().out)


def _profile(tmp_path: Path, old: str = "", new: str = "") -> Path:
    path = tmp_path / "bench.toml"
    path.write_text(PROFILE.replace(old, new) if old else PROFILE)
    return path


def _verdicts(result: dict) -> dict[str, str]:
    return {record["name"]: record["verdict"] for record in result["hints"]}


def test_a_rolling_shutter_film_told_only_by_its_profile_finds_the_truth(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path))
    assert status == 0, result["warnings"]
    assert result["latency_ms"] == pytest.approx(truth_ms, abs=TOLERANCE_MS)
    assert result["ci95_ms"][0] <= truth_ms <= result["ci95_ms"][1]
    assert result["rolling_shutter"]["readout_source"] == "given" and result["rolling_shutter"]["readout_ms"] == READOUT_MS
    verdicts = _verdicts(result)
    assert verdicts == {
        "fps": "agrees", "exposure_ms": "agrees", "readout_ms": "cannot check", "display_hz": verdicts["display_hz"],
        "led_side": "agrees", "led_row": "agrees", "sphere_row": "agrees",
    }  # fmt: skip
    assert verdicts["display_hz"] in ("agrees", "cannot check")
    readout = next(record for record in result["hints"] if record["name"] == "readout_ms")
    assert readout["source"] == f"{tmp_path / 'bench.toml'} [camera] readout_ms: rig calibrate-camera 2026-11-28 from flash.mp4"


def test_the_command_line_wins_over_the_profile_and_the_result_says_so(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path, 'led_side = "left"', 'led_side = "right"'), "--led-side", "left")
    assert status == 0, result["warnings"]
    side = next(record for record in result["hints"] if record["name"] == "led_side")
    assert side["verdict"] == "overruled" and side["used"] == "the options' led_side left"
    assert result["latency_ms"] == pytest.approx(truth_ms, abs=TOLERANCE_MS)


def test_a_profile_written_by_rig_plan_gives_the_answer_of_the_options_it_prints(film, tmp_path, capsys, monkeypatch) -> None:
    # What `rig plan --display-hz 60 --camera-fps 240` recommends for this camera, as its service returns it.
    request = PlanRequest(display_hz=DISPLAY_HZ, camera_fps=(FPS,))
    best = Setting(FPS, 1.0, 4, 0.0, 4.0, 0.2, 0.0, 0.05, 4.0, 0.5)
    canned = Plan(request, (best,), best, {"half_width_ms": 0.5, "error_ms": 0.05}, {"advice": "", "led_roi": [], "sphere_roi": []})
    monkeypatch.setattr("rig.service.plan", lambda *arguments: canned)
    profile = tmp_path / "bench.toml"
    assert main(["plan", "--display-hz", "60", "--camera-fps", "240", "--bench", str(profile)]) == 0
    analyse_line = next(line for line in capsys.readouterr().out.splitlines() if line.strip().startswith("rig analyse"))
    options = shlex.split(analyse_line)[3:]
    video, _ = film
    assert main(["analyse", str(video), *options, "--readout-ms", str(READOUT_MS), "--json"]) == 0
    told = json.loads(capsys.readouterr().out)
    status, hinted = _analysed(capsys, video, profile, "--readout-ms", str(READOUT_MS))
    assert status == 0, hinted["warnings"]
    assert hinted["latency_ms"] == told["latency_ms"] and hinted["ci95_ms"] == told["ci95_ms"]
    assert _verdicts(hinted)["exposure_ms"] == "agrees" and _verdicts(hinted)["fps"] == "agrees"


def _warning(result: dict, *words: str) -> str:
    found = [warning for warning in result["warnings"] if all(word in warning for word in words)]
    assert len(found) == 1, result["warnings"]
    return found[0]


def test_a_refresh_the_film_contradicts_is_a_warning_naming_both(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path, "refresh_hz = 60.0", "refresh_hz = 72.0"))
    assert status == EXIT_WARNINGS and _verdicts(result)["display_hz"] == "contradicts"
    _warning(result, "refreshes at 72 Hz", "rules out 72 Hz", "allows 60")
    assert result["ci95_ms"][0] <= truth_ms <= result["ci95_ms"][1]


def test_a_frame_rate_the_film_contradicts_is_a_warning_and_the_camera_values_are_left_out(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path, "fps = 240.0", "fps = 120.0"))
    assert status == EXIT_WARNINGS and _verdicts(result)["fps"] == "contradicts"
    _warning(result, "films at 120 fps", "240 fps apart", "left out")
    assert result["rolling_shutter"]["readout_source"] == "bounded"
    assert result["ci95_ms"][0] <= truth_ms <= result["ci95_ms"][1]


def test_an_exposure_the_film_contradicts_is_a_warning_and_the_blur_is_used(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path, f"exposure_ms = {EXPOSURE_MS:.4f}", "exposure_ms = 1.0"))
    assert status == EXIT_WARNINGS and _verdicts(result)["exposure_ms"] == "contradicts"
    _warning(result, "exposes 1 ms", "LED's motion blur shows")
    assert result["sampling"]["exposure"]["source"] == "LED blur"
    assert result["ci95_ms"][0] <= truth_ms <= result["ci95_ms"][1]


def test_an_led_side_the_film_contradicts_is_a_warning_and_the_evidence_is_followed(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    status, result = _analysed(capsys, video, _profile(tmp_path, 'led_side = "left"', 'led_side = "right"'))
    assert status == EXIT_WARNINGS and _verdicts(result)["led_side"] == "contradicts"
    _warning(result, "the LED is on the right", "the LED is the blob on the left")
    assert result["latency_ms"] == pytest.approx(truth_ms, abs=TOLERANCE_MS)


def test_a_readout_longer_than_the_frame_interval_is_for_another_camera_setting(film, tmp_path, capsys) -> None:
    video, truth_ms = film
    profile = _profile(tmp_path, "fps = 240.0\n", "").read_text().replace(f"readout_ms = {READOUT_MS}", "readout_ms = 6.0")
    (tmp_path / "bench.toml").write_text(profile)
    status, result = _analysed(capsys, video, tmp_path / "bench.toml")
    assert status == EXIT_WARNINGS and _verdicts(result)["readout_ms"] == "contradicts"
    _warning(result, "readout is 6 ms", "longer than the video's frame interval (4.167 ms)")
    assert result["ci95_ms"][0] <= truth_ms <= result["ci95_ms"][1]


def test_rows_the_film_contradicts_say_the_camera_or_the_bench_moved(film, tmp_path, capsys) -> None:
    video, _ = film
    status, result = _analysed(capsys, video, _profile(tmp_path, "led_row = 0.33", "led_row = 0.6"))
    assert status == EXIT_WARNINGS and _verdicts(result)["led_row"] == "contradicts"
    _warning(result, "the LED sits at 0.60", "at 0.31 in the video")
