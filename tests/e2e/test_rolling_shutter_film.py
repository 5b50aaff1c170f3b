"""Rolling-shutter films end to end, the LED 35 % of the frame's height above the sphere: a phone-like
one (variable frame timing, H.264 in an MP4), whose every frame and time the analyser reads, and a
240 fps one through `rig analyse`. Told the readout, the analyser dates each blob by its rows and
finds the truth; not told it, its latency is the truth shifted by the rows between the blobs, and
its interval reaches up to the truth on that side only, with a warning."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import analysis
from analysis.options import AnalysisOptions
from analysis.tracks import track
from rig.cli import EXIT_WARNINGS, main
from rig.film_file import FRAME_TIMES_FILE
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.tracker import TrackerConfig

FPS = 119.0  # no common display rate divides it: the display's sampling adds no bias
READOUT_S = 6e-3
JITTER_S = 1e-3
SHIFT_TOLERANCE_MS = 0.3
CORRECTED_TOLERANCE_MS = 0.3


def test_a_rolling_shutter_phone_film_reads_back_and_shifts_the_latency_by_its_rows(tmp_path: Path) -> None:
    camera = CameraConfig(
        fps=FPS, exposure_s=1 / FPS - JITTER_S, width=320, height=240, subsamples=4, readout_s=READOUT_S,
        frame_jitter_s=JITTER_S, container="mp4", codec="h264",
    )  # fmt: skip
    run = simulate(SimulationConfig(duration_s=6.0, camera=camera, layout="led-above"), tmp_path)
    film = run.truth.film
    assert film is not None and run.video_path.name == "video.mp4"
    assert film.sphere_row - film.led_row == pytest.approx(0.35, abs=0.02)

    with open(tmp_path / FRAME_TIMES_FILE, newline="") as file:
        written = np.array([float(row["t_presented"]) for row in csv.DictReader(file)])
    tracks = track(run.video_path, AnalysisOptions(led_side="left"))
    assert len(tracks.stamps) == len(written) == run.truth.frames
    np.testing.assert_array_equal(tracks.stamps - tracks.stamps[0], written)
    # stamps this close to a constant rate are taken as one (analysis.timing): the times stay within the jitter
    assert np.abs(tracks.times.t - written).max() <= JITTER_S

    result = analysis.estimate(tracks)
    shift_ms = (film.sphere_row - film.led_row) * film.readout_ms
    assert shift_ms > 1.9
    # Uncorrected: the sphere, lower in the frame, is filmed later than the LED by shift_ms.
    assert result.latency_ms == pytest.approx(run.truth.latency_ms - shift_ms, abs=SHIFT_TOLERANCE_MS)
    low, high = result.ci95_ms
    assert low <= run.truth.latency_ms <= high
    assert any("rolling shutter" in warning for warning in result.warnings)

    corrected = analysis.estimate(tracks, AnalysisOptions(led_side="left", readout_ms=film.readout_ms))
    assert corrected.latency_ms == pytest.approx(run.truth.latency_ms, abs=CORRECTED_TOLERANCE_MS)
    assert corrected.ci95_ms[0] <= run.truth.latency_ms <= corrected.ci95_ms[1]
    assert not any("rolling shutter" in warning for warning in corrected.warnings)


def test_a_240_fps_rolling_shutter_told_its_readout_finds_the_truth(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # 3.5 ms of readout, the sphere 35 % of the frame below the LED: 1.2 ms between their rows. The
    # camera exposes whole frames of a 60 Hz display (four exposures tile a refresh: no sampling bias).
    camera = CameraConfig(fps=240.0, width=320, height=240, subsamples=4, readout_s=3.5e-3)
    run = simulate(SimulationConfig(duration_s=4.0, camera=camera, layout="led-above", display=DisplayConfig(refresh_hz=60.0)), tmp_path)
    truth_ms = run.truth.latency_ms
    known = ["--led-side", "left", "--display-hz", "60", "--exposure-ms", f"{1e3 / 240}", "--json"]

    assert main(["analyse", str(run.video_path), *known, "--readout-ms", "3.5"]) == 0
    told = json.loads(capsys.readouterr().out)
    assert told["latency_ms"] == pytest.approx(truth_ms, abs=CORRECTED_TOLERANCE_MS)
    assert told["ci95_ms"][0] <= truth_ms <= told["ci95_ms"][1]
    assert told["rolling_shutter"]["readout_source"] == "given" and told["rolling_shutter"]["readout_ms"] == 3.5

    assert main(["analyse", str(run.video_path), *known]) == EXIT_WARNINGS
    bounded = json.loads(capsys.readouterr().out)
    shutter = bounded["rolling_shutter"]
    rows = shutter["sphere_row"] - shutter["led_row"]
    assert rows / 240 == pytest.approx(0.35, abs=0.03)
    assert shutter["readout_source"] == "bounded" and shutter["bias_bound_ms"] == pytest.approx(rows / 240 * 1e3 / 240)
    # Read short by the rows' share of the readout; the interval reaches later by the most any readout allows.
    assert bounded["latency_ms"] == pytest.approx(truth_ms - rows / 240 * 3.5, abs=CORRECTED_TOLERANCE_MS)
    low, high = bounded["ci95_ms"]
    assert low <= truth_ms <= high
    assert high - bounded["latency_ms"] > shutter["bias_bound_ms"] > 3 * (bounded["latency_ms"] - low)
    (warning,) = [w for w in bounded["warnings"] if "rolling shutter" in w]
    assert "rows below the LED" in warning and "--readout-ms" in warning


def test_a_rolling_shutter_told_its_readout_at_rates_locked_to_the_display(tmp_path: Path) -> None:
    # 120 fps exposing 4 ms of each 60 Hz refresh: two phases a refresh, and the display's sampling
    # biases the film by 1.2 ms. Dated by its rows, each of the sphere's frames lies a little off the
    # two phases, by where the swing has it; folded by those dates, the frames of one phase split
    # between neighbouring bins by the swing's position, and the tracks' slow errors once read as a
    # switch between them: a narrow interval of the wrong sign, 0.9 ms from the truth.
    camera = CameraConfig(fps=120.0, exposure_s=4e-3, readout_s=4e-3, width=320, height=240, subsamples=4)
    config = SimulationConfig(
        duration_s=4.0, seed=11, predictor="hold", warmup_s=0.522, layout="0.27,0.3189,0.4/0.73,0.6811,0.42", camera=camera,
        display=DisplayConfig(refresh_hz=60.0, phase=0.5113900218032627), tracker=TrackerConfig(transport_delay_s=0.022),
    )  # fmt: skip
    run = simulate(config, tmp_path)
    result = analysis.analyse(run.video_path, AnalysisOptions(led_side="left", display_hz=60.0, exposure_ms=4.0, readout_ms=4.0))
    truth_ms = run.truth.latency_ms
    assert abs(result.methods["sinefit"].details["measured_ms"] - truth_ms) > 1.0  # the sampling's bias, not the shutter's
    assert result.ci95_ms[0] <= truth_ms <= result.ci95_ms[1]
