"""A phone-like film end to end: rolling shutter, variable frame timing, H.264 in an MP4, the LED
35 % of the frame's height above the sphere. The analyser reads every frame and its own time; not
yet told the readout, its latency is the truth shifted by the rows between the blobs."""

import csv
from pathlib import Path

import numpy as np
import pytest

import analysis
from analysis.options import AnalysisOptions
from analysis.tracks import track
from rig.film_file import FRAME_TIMES_FILE
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig

FPS = 119.0  # no common display rate divides it: the display's sampling adds no bias
READOUT_S = 6e-3
JITTER_S = 1e-3
SHIFT_TOLERANCE_MS = 0.3


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
    # Once the analyser dates each blob by its rows (given the readout), its answer is to be checked
    # against run.truth.latency_ms itself, within 0.3 ms and covered by its interval, here.
