"""`rig analyse` of many videos: the summary, its labels and plot, and what it refuses before work."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from rig.cli import EXIT_USER_ERROR, EXIT_WARNINGS, main


def rows_of(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as stream:
        return list(csv.DictReader(stream))


def test_a_batch_with_a_bad_video_writes_every_row_labelled_and_exits_with_warnings(small_runs, tmp_path: Path, capsys) -> None:
    labels = tmp_path / "labels.csv"
    labels.write_text(f"video,system\n{small_runs['fast']},A\n{small_runs['slow']},B\nvideo.avi,broken\n")
    summary = tmp_path / "summary.csv"
    videos = [str(small_runs[name]) for name in ("fast", "broken", "slow")]
    code = main(["analyse", *videos, "--summary", str(summary), "--labels", str(labels)])
    out = capsys.readouterr().out
    assert code == EXIT_WARNINGS
    rows = rows_of(summary)
    assert [row["video"] for row in rows] == videos
    assert [row["status"] for row in rows] == ["warning", "failed", "warning"]
    assert [row["system"] for row in rows] == ["A", "broken", "B"]
    assert rows[1]["error"] and not rows[1]["latency_ms"]
    assert all(float(row["ci95_low_ms"]) <= float(row["latency_ms"]) <= float(row["ci95_high_ms"]) for row in (rows[0], rows[2]))
    assert json.loads(summary.with_suffix(".json").read_text())["partial"] is False
    assert summary.with_suffix(".png").stat().st_size > 10_000
    assert "3 videos: 0 ok, 2 with warnings, 1 failed" in out


def test_json_prints_the_rows_in_the_order_given(small_runs, capsys) -> None:
    code = main(["analyse", str(small_runs["slow"]), str(small_runs["fast"]), "--json"])
    rows = json.loads(capsys.readouterr().out)
    assert code == EXIT_WARNINGS  # 120 fps cannot see a 60 Hz display's refresh: the interval allows for it
    assert [row["status"] for row in rows] == ["warning", "warning"]
    assert [row["video"] for row in rows] == [str(small_runs["slow"]), str(small_runs["fast"])]
    assert rows[0]["period_s"] > rows[1]["period_s"]


def test_an_existing_summary_is_kept_without_overwrite(small_runs, tmp_path: Path, capsys) -> None:
    summary = tmp_path / "summary.csv"
    summary.write_text("a lab's earlier summary\n")
    code = main(["analyse", str(small_runs["fast"]), str(small_runs["slow"]), "--summary", str(summary)])
    assert code == EXIT_USER_ERROR
    assert "--overwrite" in capsys.readouterr().err
    assert summary.read_text() == "a lab's earlier summary\n"


def test_one_video_options_are_refused_for_a_batch(small_runs, tmp_path: Path, capsys) -> None:
    code = main(["analyse", str(small_runs["fast"]), str(small_runs["slow"]), "--csv", str(tmp_path / "t.csv")])
    assert code == EXIT_USER_ERROR
    assert "--csv is for one video" in capsys.readouterr().err
    assert not (tmp_path / "t.csv").exists()


def test_an_unknown_group_label_is_refused_before_work(small_runs, tmp_path: Path, capsys) -> None:
    code = main(["analyse", str(small_runs["fast"]), str(small_runs["slow"]), "--summary", str(tmp_path / "s.csv"),
                 "--group", "system"])  # fmt: skip
    assert code == EXIT_USER_ERROR
    assert "--group system: no such label (labels: folder)" in capsys.readouterr().err
    assert not (tmp_path / "s.csv").exists()


def test_an_unreachable_scheduler_is_a_one_line_error(small_runs, tmp_path: Path, capsys) -> None:
    code = main(["analyse", str(small_runs["fast"]), str(small_runs["slow"]), "--summary", str(tmp_path / "s.csv"),
                 "--scheduler", "tcp://127.0.0.1:9"])  # fmt: skip
    assert code == EXIT_USER_ERROR
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "scheduler" in err
