"""The tracks CSV: one row per frame, empty coordinates where a blob was missing."""

import csv

import numpy as np
import pytest

from analysis import analyse, write_tracks_csv


def test_tracks_csv_has_a_row_per_frame(tmp_path, scene, render_video):
    clip = scene(latency_s=0.03, duration_s=2.5)
    frames = render_video(clip).copy()
    frames[10, :, 80:] = 21
    result = analyse(frames, fps=clip.fps)
    path = tmp_path / "tracks.csv"
    write_tracks_csv(path, result)
    with path.open(newline="") as stream:
        rows = list(csv.reader(stream))
    assert rows[0] == ["t", "led_x", "led_y", "led_valid", "sphere_x", "sphere_y", "sphere_valid"]
    assert len(rows) == clip.frame_count + 1
    assert rows[11][4:] == ["", "", "0"]
    assert rows[12][6] == "1"
    table = np.array([[float(value) for value in row] for row in rows[1:] if row[6] == "1"])
    assert table[:, 0] == pytest.approx(np.delete(result.led_track.t, 10), abs=1e-6)
    assert table[:, 1] == pytest.approx(np.delete(result.led_track.x, 10), abs=1e-4)
    assert table[:, 5] == pytest.approx(np.delete(result.sphere_track.y, 10), abs=1e-4)
