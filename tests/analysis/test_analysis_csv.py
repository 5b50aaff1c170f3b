"""The tracks CSV: one format, written row by row while tracking, replaced by the final table at the end."""

import csv

import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions, analyse
from analysis.tracks_csv import TRACKS_CSV_HEADER

COLUMN = {name: index for index, name in enumerate(TRACKS_CSV_HEADER)}


def read(path):
    with path.open(newline="") as stream:
        return list(csv.reader(stream))


def test_tracks_csv_has_a_row_per_frame_with_the_final_times(tmp_path, scene, render_video):
    clip = scene(latency_s=0.03, duration_s=2.5, fps=120.0)
    frames = render_video(clip).copy()
    frames[10, :, 80:] = 21
    path = tmp_path / "tracks.csv"
    result = analyse(frames, AnalysisOptions(fps=clip.fps, method="fft"), tracks_csv=path)
    rows = read(path)
    assert tuple(rows[0]) == TRACKS_CSV_HEADER
    assert len(rows) == clip.frame_count + 1
    assert [rows[11][COLUMN[name]] for name in ("sphere_x", "sphere_y", "sphere_valid")] == ["", "", "0"]
    assert rows[12][COLUMN["sphere_valid"]] == "1"
    table = np.array([[float(v) if v else np.nan for v in row] for row in rows[1:]])
    assert table[:, COLUMN["frame"]] == pytest.approx(np.arange(clip.frame_count))
    assert table[:, COLUMN["stamp_s"]] == pytest.approx(np.arange(clip.frame_count) / clip.fps, abs=1e-6)
    assert table[:, COLUMN["t"]] == pytest.approx(result.led_track.t, abs=1e-6)
    assert table[:, COLUMN["led_x"]] == pytest.approx(result.led_track.x, abs=1e-4, nan_ok=True)
    assert table[:, COLUMN["sphere_y"]] == pytest.approx(result.sphere_track.y, abs=1e-4, nan_ok=True)
    assert not (tmp_path / "tracks.csv.partial").exists()


def test_tracks_measured_before_a_failure_are_kept(tmp_path, scene, render_video):
    clip = scene(period_s=1.0, duration_s=1.6, fps=120.0)
    path = tmp_path / "tracks.csv"
    with pytest.raises(AnalysisError, match="periods"):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps), tracks_csv=path)
    rows = read(path)
    assert len(rows) == clip.frame_count + 1
    assert all(row[COLUMN["led_valid"]] == "1" for row in rows[1:])


def test_tracks_are_on_disk_as_the_video_is_tracked(tmp_path, scene, render_video):
    clip = scene(duration_s=4.1, fps=120.0)
    path = tmp_path / "tracks.csv"
    seen = []

    def progress(done, total):
        rows = read(path)
        seen.append((done, len(rows) - 1, tuple(rows[0]), {row[COLUMN["t"]] for row in rows[1:]}))

    analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"), tracks_csv=path, progress=progress)
    # Rows are flushed in blocks: by the time 128 frames are tracked, at least the first 64 are on disk.
    assert read(path)[0] and seen[1][0] == 128 and seen[1][1] >= 64
    # The rows written while tracking have the final table's columns; the frame times are not decided yet.
    assert seen[1][2] == TRACKS_CSV_HEADER and seen[1][3] == {""}


def test_an_interrupted_analysis_keeps_every_frame_it_tracked(tmp_path, scene, render_video):
    clip = scene(duration_s=4.1, fps=120.0)
    path = tmp_path / "tracks.csv"

    def progress(done, total):
        if done == 128:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        analyse(render_video(clip), AnalysisOptions(fps=clip.fps, method="fft"), tracks_csv=path, progress=progress)
    rows = read(path)
    assert tuple(rows[0]) == TRACKS_CSV_HEADER
    assert [int(row[COLUMN["frame"]]) for row in rows[1:]] == list(range(128))
    stamps = np.array([float(row[COLUMN["stamp_s"]]) for row in rows[1:]])
    assert stamps == pytest.approx(np.arange(128) / clip.fps, abs=1e-6)
    assert all(row[COLUMN["led_valid"]] == "1" and row[COLUMN["led_x"]] for row in rows[1:])
