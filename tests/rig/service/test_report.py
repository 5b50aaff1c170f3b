"""Reports: one page with everything, nothing fetched; plots a person can read."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest

from rig.cli import main
from rig.errors import ConfigError
from rig.report.figures import latency_over_time_figure, residuals_figure, summary_figure, tracks_figure
from rig.service.analyse import AnalysisRequest, analyse
from rig.service.batch import BatchItem, run_batch


@pytest.fixture(scope="module")
def result(small_runs):
    return analyse(AnalysisRequest(small_runs["fast"])).result


def test_run_figures_label_their_axes_and_keep_legends_off_the_data(result, legends_clear_of_data) -> None:
    for make in (tracks_figure, latency_over_time_figure, residuals_figure):
        legends_clear_of_data(make(result))


def test_the_tracks_show_the_whole_film(result) -> None:
    figure = tracks_figure(result)
    whole = figure.axes[0]
    low, high = whole.get_xlim()
    assert low <= result.led_track.t[0] + 0.05 and high >= result.led_track.t[-1] - 0.05


def test_a_run_report_is_one_self_contained_page_and_markdown(small_runs, tmp_path: Path, capsys) -> None:
    out = tmp_path / "report.html"
    assert main(["report", str(small_runs["fast"].parent), "--out", str(out)]) == 0
    page = out.read_text()
    assert "simulated truth" in page and "Diagnostics" in page and "project commit" in page
    assert not re.search(r"(src|href)=['\"]https?:", page)
    assert page.count("data:image/png;base64,") == 3
    markdown = out.with_suffix(".md").read_text()
    assert "![tracks](report_files/tracks.png)" in markdown and (tmp_path / "report_files" / "tracks.png").exists()
    assert "wrote" in capsys.readouterr().out


def test_a_summary_report_compares_the_runs(small_runs, tmp_path: Path, legends_clear_of_data) -> None:
    items = [BatchItem(AnalysisRequest(small_runs[name]), {"system": name}) for name in ("fast", "slow", "broken")]
    run_batch(items, tmp_path / "summary.csv")
    assert main(["report", str(tmp_path / "summary.csv"), "--out", str(tmp_path / "summary.html")]) == 0
    page = (tmp_path / "summary.html").read_text()
    assert "2 of 3 videos measured" in page and "By system" in page and "slow - fast" in page
    rows = [{"video": str(small_runs[n]), "latency_ms": value, "ci95_low_ms": value - 1, "ci95_high_ms": value + 1,
             "frequency_hz": frequency, "system": n} for n, value, frequency in (("fast", 40.0, 1.4), ("slow", 42.0, 0.8))]  # fmt: skip
    figure = summary_figure(rows, "system")
    assert len(figure.axes) == 2
    legends_clear_of_data(figure)


def test_a_group_whose_first_video_failed_keeps_its_legend_entry_and_an_all_failed_batch_has_none() -> None:
    failed = {"latency_ms": None, "error": "video file missing", "frequency_hz": None}
    rows = [{**failed, "video": "a1.avi", "system": "a"}, {"video": "a2.avi", "latency_ms": 40.0, "ci95_low_ms": 39.0,
            "ci95_high_ms": 41.0, "frequency_hz": 1.0, "system": "a"}, {**failed, "video": "b1.avi", "system": "b"}]  # fmt: skip
    legend = summary_figure(rows, "system").axes[0].get_legend()
    assert [text.get_text() for text in legend.get_texts()] == ["a"]
    assert summary_figure([rows[0], rows[2]], "system").axes[0].get_legend() is None


def test_a_report_needs_an_html_file_in_an_existing_folder(small_runs, tmp_path: Path) -> None:
    assert main(["report", str(small_runs["fast"]), "--out", str(tmp_path / "report.pdf")]) == 2
    assert main(["report", str(small_runs["fast"]), "--out", str(tmp_path / "no" / "report.html")]) == 2
    with pytest.raises(ConfigError):
        from rig.service.report import read_summary

        read_summary(tmp_path / "missing.csv")


def _sweep_summary(path: Path) -> Path:
    """A sweep's summary as `rig sweep` writes it: two periods, two predictors, the truth beside each row."""
    columns = ("index", "video", "status", "latency_ms", "ci95_low_ms", "ci95_high_ms", "frequency_hz", "truth_ms", "error_ms", "warnings", "error",
               "predictor", "pendulum.period_s", "camera.impairments.mirrored", "span")  # fmt: skip
    rows = []
    for index, (predictor, period, measured, truth) in enumerate(
        (("hold", 1.0, 1.05, 1.0), ("hold", 1.0, 0.95, 1.0), ("hold", 2.0, 3.1, 3.0), ("slerp", 1.0, 0.5, 0.45), ("slerp", 2.0, 2.2, 2.25))
    ):
        rows.append((index, f"point{index:03d}/video.avi", "ok", measured, measured - 0.2, measured + 0.2, 1 / period, truth, measured - truth, "", "",
                     predictor, period, False, "[0.0, 9.991666666666667]"))  # fmt: skip
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(columns)
        writer.writerows(rows)
    return path


def test_a_sweeps_report_shows_truth_error_and_every_swept_setting_for_people(tmp_path: Path) -> None:
    assert main(["report", str(_sweep_summary(tmp_path / "summary.csv")), "--group", "predictor", "--out", str(tmp_path / "sweep.html")]) == 0
    markdown = (tmp_path / "sweep.md").read_text()
    for header in ("true (ms)", "error (ms)", "predictor", "pendulum.period_s", "camera.impairments.mirrored", "span"):
        assert f" {header} |" in markdown
    assert "False" not in markdown and "9.991666666666667" not in markdown and "[0.0" not in markdown
    assert "| point000/video.avi | ok | hold | 1 | no | 0, 9.992 | 1.05 | 0.85 | 1.25 | 1 | 0.05 |" in markdown
    by_predictor = markdown.split("## By predictor")[1].split("## ")[0]
    assert "| hold | 1 | no | 0, 9.992 | 2 | 1 | " in by_predictor  # the two 1 s runs pooled, truth 1 ms
    assert "| hold | 2 | no | 0, 9.992 | 1 | 3.1 | " in by_predictor  # the 2 s run apart
    assert by_predictor.count("slerp - hold") == 2  # compared under each period, never across them
