"""`rig calibrate-camera FILM --flash-hz F`: the readout and exposure of a simulated camera, printed,
as JSON or into a bench profile; one line and exit status 2 where the film or the options cannot decide."""

import json
from pathlib import Path

import pytest

from rig.cli import main
from rig.service import SimulationConfig, simulate
from rig.service.bench_profile import read_profile
from rig.sim.camera import CameraConfig
from rig.sim.flash import FlashTarget

READOUT_S, EXPOSURE_S, FLASH_HZ = 7e-3, 2e-3, 81.3


@pytest.fixture(scope="module")
def light_film(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 120 fps camera with a 7 ms readout exposing 2 ms, filming a light flashing at 81.3 Hz, on 25 % of each period."""
    camera = CameraConfig(fps=120, exposure_s=EXPOSURE_S, readout_s=READOUT_S, width=160, height=120)
    config = SimulationConfig(duration_s=1.0, camera=camera, flash=FlashTarget("light", hz=FLASH_HZ, duty=0.25))
    return simulate(config, tmp_path_factory.mktemp("light")).video_path


def test_the_readout_and_exposure_are_printed_with_what_the_film_showed(light_film, capsys):
    assert main(["calibrate-camera", str(light_film), "--flash-hz", str(FLASH_HZ), "--duty", "0.25"]) == 0
    readout, exposure, film = capsys.readouterr().out.splitlines()
    assert readout.startswith("readout 7.0") and "rows read top-down" in readout
    assert exposure.startswith("exposure 2.0") or exposure.startswith("exposure 1.9")
    assert "the light flashing at 81.3 Hz" in film and "on 25." in film


def test_json_gives_si_fields_a_bench_profile_can_take(light_film, capsys):
    assert main(["calibrate-camera", str(light_film), "--flash-hz", str(FLASH_HZ), "--duty", "0.25", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["readout_s"] == pytest.approx(READOUT_S, rel=0.05)
    assert record["exposure_s"] == pytest.approx(EXPOSURE_S, rel=0.10)
    assert record["fps"] == pytest.approx(120.0, rel=1e-6)
    assert record["readout_ci95_s"][0] <= READOUT_S <= record["readout_ci95_s"][1]
    assert record["global_shutter"] is False and record["warnings"] == []


@pytest.mark.parametrize(
    "arguments, words",
    [
        (["--duty", "0.5"], "not the 50% given: check --duty"),
        (["--duty", "fit"], "cannot tell an exposure"),
        (["--flash-hz", "95"], "do not follow a light flashing at 95 Hz"),
        (["--source", "display"], "give its refresh rate (--display-hz)"),
        (["--display-hz", "60"], "give --source display with it"),
        (["--roi", "0,0,400,50"], "does not lie within the 160x120 frame"),
    ],
)
def test_what_cannot_decide_is_one_line_and_status_2(light_film, capsys, arguments, words):
    flash = [] if "--flash-hz" in arguments else ["--flash-hz", str(FLASH_HZ)]
    duty = [] if "--duty" in arguments else ["--duty", "0.25"]
    assert main(["calibrate-camera", str(light_film), *flash, *duty, *arguments]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and error.startswith("rig calibrate-camera: error: ")
    assert words in error


def test_a_missing_film_is_one_line(tmp_path, capsys):
    assert main(["calibrate-camera", str(tmp_path / "none.mp4"), "--flash-hz", "80"]) == 2
    assert "does not exist" in capsys.readouterr().err


def test_the_flash_frequency_is_required(light_film, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["calibrate-camera", str(light_film)])
    assert exit_.value.code == 2
    assert "--flash-hz" in capsys.readouterr().err


def test_bench_writes_the_measured_readout_exposure_and_frame_rate_into_the_profile(light_film, tmp_path, capsys):
    profile = tmp_path / "bench.toml"
    profile.write_text('# our phone\n[display]\nrefresh_hz = 60.0\n')
    assert main(["calibrate-camera", str(light_film), "--flash-hz", str(FLASH_HZ), "--duty", "0.25", "--bench", str(profile)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"bench profile {profile}: wrote the camera's readout, exposure and frame rate"
    camera = read_profile(profile).camera
    assert camera.readout_ms == pytest.approx(READOUT_S * 1e3, rel=0.05)
    assert camera.exposure_ms == pytest.approx(EXPOSURE_S * 1e3, rel=0.10)
    assert camera.fps == pytest.approx(120.0, rel=1e-4) and camera.readout_direction == "top-down"
    assert camera.readout_ci95_ms[0] <= READOUT_S * 1e3 <= camera.readout_ci95_ms[1]
    assert camera.readout_source.startswith("rig calibrate-camera ") and camera.readout_source.endswith(f"from {light_film.name}")
    assert profile.read_text().startswith("# our phone\n[display]\nrefresh_hz = 60.0\n")
