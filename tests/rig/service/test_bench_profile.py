"""The bench profile: its keys declared once and checked as they are read (a bad file is one line,
exit status 2), written back changing only what is set, and turned into the analysis's hints, each
with its source; what `rig plan` and `rig calibrate-camera` write into it."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis import AnalysisOptions
from analysis.hints import Hint
from analysis.shutter import ShutterResult
from rig.cli import main
from rig.errors import ConfigError
from rig.service.bench_profile import BenchProfile, CameraProfile, read_profile, shutter_display, with_profile, write_profile
from rig.service.calibrate import bench_changes
from rig.service.plan import Plan, PlanRequest, Setting
from rig.service.sweep import read_sweep

CALIBRATED = """# the lab's phone, filmed 2026-11-28
[camera]
fps = 120.0  # slow motion
readout_ms = 7.02
readout_ci95_ms = [6.97, 7.08]
readout_source = "rig calibrate-camera 2026-11-28 from flash.mp4"

[layout]
led_side = "left"
source = "the LED left of the monitor"
"""


def test_a_written_profile_reads_back_with_what_it_held_and_its_comments(tmp_path: Path) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(CALIBRATED)
    profile = write_profile(path, {"display": {"refresh_hz": 60.0, "refresh_source": "datasheet"}, "camera": {"exposure_ms": 2.5}})
    assert profile == read_profile(path)
    assert profile.camera.readout_ms == 7.02 and profile.camera.exposure_ms == 2.5 and profile.display.refresh_hz == 60.0
    text = path.read_text()
    assert "# the lab's phone, filmed 2026-11-28" in text and "fps = 120.0  # slow motion" in text
    assert text.index("[camera]") < text.index("[layout]") < text.index("[display]")


def test_a_key_set_to_none_is_removed_and_a_new_profile_is_made(tmp_path: Path) -> None:
    path = tmp_path / "new.toml"
    write_profile(path, {"camera": {"fps": 60.0, "readout_ms": 5.0}})
    assert read_profile(path).camera.readout_ms == 5.0
    assert write_profile(path, {"camera": {"readout_ms": None}}).camera == CameraProfile(fps=60.0)
    assert "readout_ms" not in path.read_text()


def test_a_write_that_would_not_read_back_leaves_the_file_as_it_was(tmp_path: Path) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(CALIBRATED)
    with pytest.raises(ConfigError, match="camera.readout_ms 7.02 is longer than a frame interval at 240 fps"):
        write_profile(path, {"camera": {"fps": 240.0}})
    assert path.read_text() == CALIBRATED


BAD = [
    ("[camera]\nfpss = 120.0\n", "unknown key camera.fpss; CameraProfile takes fps, fps_source, exposure_ms"),
    ("[camera]\nfps = \"fast\"\n", "camera.fps must be a number, not 'fast'"),
    ("[display]\nrefresh_hz = -60.0\n", "display.refresh_hz must be a positive number of Hz from 1 to 1000, got -60.0"),
    ("[camera\nfps = 120\n", "is not valid TOML"),
    ("[lens]\n", "unknown key lens; BenchProfile takes camera, display, layout"),
    ("[layout]\nled_roi = [0, 0, 10, 10]\n", "layout: give both regions, led_roi and sphere_roi, or neither"),
    ("[camera]\nexposure_ms = 3.0\nexposure_ci95_ms = [1.0, 2.0]\n", "camera.exposure_ms 3 lies outside its 95% interval [1.0, 2.0]"),
    ("[layout]\nled_side = \"top\"\n", "layout.led_side must be one of left, right, got 'top'"),
]


@pytest.mark.parametrize(("text", "words"), BAD)
def test_a_bad_profile_is_one_config_error_naming_the_file(tmp_path: Path, text: str, words: str) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(text)
    with pytest.raises(ConfigError) as error:
        read_profile(path)
    assert str(error.value).startswith(str(path)) and words in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize(("text", "words"), [BAD[0], BAD[1], BAD[2], BAD[3]])
def test_rig_analyse_with_a_bad_profile_is_one_line_and_exit_status_2(tmp_path, capsys, text: str, words: str) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(text)
    video = tmp_path / "video.avi"
    video.write_bytes(b"")
    assert main(["analyse", str(video), "--bench", str(path)]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and error.startswith(f"rig analyse: error: {path}") and words in error


def test_rig_measure_reads_its_profile_before_opening_any_device(tmp_path, capsys) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(BAD[0][0])
    argv = ["measure", "--tracker", "serial:/dev/null", "--camera", "camera:0", "--out", str(tmp_path / "run"), "--bench", str(path)]
    assert main(argv) == 2
    assert "unknown key camera.fpss" in capsys.readouterr().err


def test_every_value_is_a_hint_with_its_source_and_the_options_keep_their_own(tmp_path: Path) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(CALIBRATED)
    options = with_profile(AnalysisOptions(led_side="right"), read_profile(path), path)
    assert options.hints == (
        Hint("fps", 120.0, f"{path} [camera] fps"),
        Hint("readout_ms", 7.02, f"{path} [camera] readout_ms: rig calibrate-camera 2026-11-28 from flash.mp4"),
        Hint("led_side", "left", f"{path} [layout] led_side: the LED left of the monitor"),
    )
    hinted = options.hinted()
    assert hinted.readout_ms == 7.02 and hinted.led_side == "right" and hinted.fps is None


def test_a_readout_read_bottom_to_top_is_refused_for_the_analysis(tmp_path: Path) -> None:
    path = tmp_path / "bench.toml"
    path.write_text(CALIBRATED.replace("readout_ms = 7.02", 'readout_ms = 7.02\nreadout_direction = "bottom-up"'))
    with pytest.raises(ConfigError, match="reads its rows bottom to top"):
        with_profile(AnalysisOptions(), read_profile(path), path)
    assert with_profile(AnalysisOptions(readout_ms=0.0), read_profile(path), path).readout_ms == 0.0


def test_a_flashing_display_takes_its_refresh_and_scanout_from_the_profile(tmp_path: Path) -> None:
    assert shutter_display(BenchProfile()) == {}
    path = tmp_path / "bench.toml"
    path.write_text('[display]\nrefresh_hz = 144.0\nscanout = "bottom-up"\n')
    assert shutter_display(read_profile(path)) == {"display_hz": 144.0, "scanout": "bottom-up"}


def _plan(fps: float) -> Plan:
    best = Setting(fps, 1.0, None, 0.0, 4.0, 0.2, 0.0, 0.05, 6.0, 0.5)
    return Plan(PlanRequest(display_hz=60.0, camera_fps=(fps,)), (best,), best, None, {})


def test_a_plan_writes_the_display_and_its_camera_setting_and_drops_a_readout_for_another_rate() -> None:
    calibrated = CameraProfile(fps=120.0, readout_ms=7.02)
    same = _plan(120.0).bench_changes(calibrated, "2026-11-29")
    assert same["display"] == {"refresh_hz": 60.0, "refresh_source": "rig plan 2026-11-29"}
    assert same["camera"]["fps"] == 120.0 and same["camera"]["exposure_ms"] == 8.33333 and "readout_ms" not in same["camera"]
    other = _plan(200.0).bench_changes(calibrated, "2026-11-29")
    assert other["camera"]["readout_ms"] is None and other["camera"]["readout_source"] is None
    unreached = Plan(PlanRequest(display_hz=60.0, camera_fps=(30.0,)), (), None, None, {}).bench_changes(calibrated, "2026-11-29")
    assert set(unreached) == {"display"}


def test_a_calibration_writes_its_readout_exposure_and_frame_rate_with_their_intervals() -> None:
    result = ShutterResult(
        readout_s=7.02e-3, readout_ci95_s=(6.97e-3, 7.08e-3), exposure_s=2.01e-3, exposure_ci95_s=(1.95e-3, 2.08e-3),
        fps=119.99, line_time_s=7.02e-3 / 480, global_shutter=False, readout_direction="top-down", source="light",
        flash_hz=81.3, flash_hz_seen=81.3, duty=0.25, band_periods=0.6, ramp_rows=12.0, rows=(0, 479), row_count=480,
        frame_height=480, frames=120, lit_pixels=1000, saturated_pixels=0, timing_source="container timestamps",
        timing_rms_s=1e-5, misfit=0.01,
    )  # fmt: skip
    camera = bench_changes(result, Path("films/flash.mp4"), "2026-11-28")["camera"]
    assert camera["readout_ms"] == 7.02 and camera["readout_ci95_ms"] == (6.97, 7.08) and camera["readout_direction"] == "top-down"
    assert camera["exposure_ms"] == 2.01 and camera["fps"] == 119.99
    assert camera["readout_source"] == "rig calibrate-camera 2026-11-28 from flash.mp4"
    assert CameraProfile(**camera).readout_ms == 7.02


def test_a_sweep_names_its_profile_from_its_own_folder(tmp_path: Path) -> None:
    (tmp_path / "profiles").mkdir()
    (tmp_path / "profiles" / "bench.toml").write_text(CALIBRATED)
    spec = tmp_path / "sweep.toml"
    spec.write_text('[grid]\nseed = [1]\n\n[analysis]\nbench = "profiles/bench.toml"\n')
    options = read_sweep(spec).points(tmp_path / "out")[0].analysis.options
    assert [hint.name for hint in options.hints] == ["fps", "readout_ms", "led_side"]
    assert options.hints[0].source == f"{tmp_path / 'profiles' / 'bench.toml'} [camera] fps"
    (tmp_path / "profiles" / "bench.toml").write_text(BAD[0][0])
    with pytest.raises(ConfigError, match=r"sweep.toml: .*bench.toml: unknown key camera.fpss"):
        read_sweep(spec)
