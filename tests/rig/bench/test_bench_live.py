"""`rig bench live`'s figures from a live run's files, its table, notes and plot (the live run
itself needs an X display: the bench is a command, not a test)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rig.bench import live


def _csv(path: Path, header: str, *rows: tuple[float, ...]) -> None:
    path.write_text(header + "\n" + "".join(",".join(f"{v:g}" for v in row) + "\n" for row in rows))


def test_arrival_to_pose_is_each_pose_less_the_arrival_of_the_newest_sample_behind_it(tmp_path: Path) -> None:
    _csv(tmp_path / "tracker.csv", "t_sensor,t_arrival,px", (0.000, 0.001, 0.0), (0.001, 0.0025, 0.0), (0.002, 0.0031, 0.0))
    _csv(tmp_path / "published_poses.csv", "frame,t_pose,t_sensor", (0, 0.004, 0.001), (1, 0.020, 0.002), (2, 0.030, 0.5))
    _csv(tmp_path / "app_frames.csv", "index,t_start", (0, 0.0035), (1, 0.017))
    figures = live.arrival_to_pose(tmp_path)
    waits = figures["arrival_to_pose"]  # frame 2's sample never arrived: left out
    assert waits["count"] == 2
    assert waits["median_us"] == pytest.approx((1500 + 16900) / 2) and waits["max_us"] == pytest.approx(16900)
    own = figures["frame_start_to_pose"]
    assert own["count"] == 2 and own["median_us"] == pytest.approx((500 + 3000) / 2) and own["max_us"] == pytest.approx(3000)


REPORT = {
    "arrival_to_pose": {"count": 600, "median_us": 9000.0, "p95_us": 16000.0, "max_us": 17500.0},
    "frame_start_to_pose": {"count": 600, "median_us": 450.0, "p95_us": 900.0, "max_us": 2400.0},
    "swap_to_log": {"count": 300, "median_us": 35.0, "p95_us": 80.0, "max_us": 400.0},
    "cpus": 2, "load_average_1min": 1.234,
}  # fmt: skip


def test_the_table_notes_and_plot_show_every_figure(tmp_path: Path) -> None:
    lines = live.table(REPORT).splitlines()
    assert lines[1].split() == ["sample", "arrival", "to", "pose", "600", "9000", "16000", "17500"]
    assert lines[3].split() == ["swap", "to", "logged", "300", "35", "80", "400"]
    assert len(lines) == 4
    verdict = "degraded: the rig hitched: no new image for 150 ms from 2.0 s into the run"
    assert live.table({**REPORT, "run_health": verdict}).splitlines()[4] == f"the live run's health: {verdict}"
    assert live.BENCH.notes(REPORT) == "machine noise: 2 CPUs, 1-minute load average 1.23"
    live.plot(REPORT, tmp_path / "live.png")
    assert (tmp_path / "live.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / "live.png").stat().st_size > 10_000
