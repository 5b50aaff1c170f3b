"""The tracker bench's parts on a short case: what it counts must be what the emulator sent."""

from __future__ import annotations

import math
from pathlib import Path

from rig.bench import trackers


def test_a_clean_pty_case_counts_every_record_sent_and_measures_its_costs(tmp_path: Path) -> None:
    case = trackers.Case("serial", "pty", "binary-pose", "none")
    row = trackers.run_case(case, rate_hz=200.0, duration_s=1.0, folder=tmp_path / "case", log=lambda line: None)
    assert row["sent"] == row["recorded"] == 200
    assert (row["missing"], row["fabricated"], row["corrupt"]) == (0, 0, 0)
    assert row["in_order"]
    assert 0 < row["reader_us_per_sample"] <= row["reading_us_per_sample"] <= row["us_per_sample"]
    assert 0 <= row["latency_ms_median"] <= row["latency_ms_p95"]


def test_the_wake_floor_is_a_cost_per_record_of_the_bare_reader(tmp_path: Path) -> None:
    floor = trackers.wake_floor(rate_hz=200.0, duration_s=0.5, folder=tmp_path)
    assert math.isfinite(floor) and floor > 0


def test_the_table_and_the_plot_show_every_row(tmp_path: Path) -> None:
    row = {
        "failed": None, "source": "serial", "transport": "pty", "profile": "csv", "faults": "corrupt=0.01,disconnect=5:0.5", "sent": 10,
        "recorded": 9, "missing": 0, "fabricated": 0, "corrupt": 1, "damaged_sent": 1, "reading_us_per_sample": 40.0,
        "reader_us_per_sample": 20.0, "us_per_sample": 70.0, "wake_floor_us": 18.0, "latency_ms_median": 0.1,
        "latency_ms_p95": 0.4, "stolen_cpu_pct": 2.5,
    }  # fmt: skip
    failed = trackers.case_fields(trackers.cases(1.0)[3], 1000.0, 2.0, "no LSL stream")
    lines = trackers.table([row, {**row, "source": "lsl", "stolen_cpu_pct": None}, failed]).splitlines()
    assert len(lines) == 5 and "40.0 (20.0), 70.0 | 18.0 | 2.5 | 0.100, 0.400 |" in lines[2]
    assert "| 18.0 | n/a | 0.100" in lines[3]
    assert lines[4] == "| lsl | lsl | pose (7 channels) | none | failed: no LSL stream |"
    trackers.plot([row, failed], tmp_path / "trackers.png")
    assert (tmp_path / "trackers.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and (tmp_path / "trackers.png").stat().st_size > 10_000


def test_the_cpu_a_host_took_is_its_share_of_the_ticks_between_two_readings() -> None:
    assert trackers.stolen_pct((10, 1000), (40, 2000)) == 3.0
    assert trackers.stolen_pct(None, (40, 2000)) is None
    assert trackers.stolen_pct((10, 1000), (10, 1000)) is None, "no time passed"
    ticks = trackers.cpu_ticks()
    if ticks is not None:
        stolen, total = ticks
        assert 0 <= stolen <= total


def test_a_case_that_could_not_run_is_a_failed_row_with_its_reason(tmp_path: Path) -> None:
    case = trackers.Case("serial", "tcp", "binary-pose", "none")
    failed = {**trackers.case_fields(case, 1000.0, 10.0, "the tracker emulator did not start: no pty"), "load_average_1min": 1.0}
    assert trackers.table([failed]).splitlines()[2] == "| serial | tcp | binary-pose | none | failed: the tracker emulator did not start: no pty |"
    assert trackers.targets([failed])["every case ran"] is False
    assert set(trackers.targets([failed]).values()) == {None, False}
    assert trackers.BENCH.all_failed([failed]) == "every one of the 1 cases failed or recorded nothing (the first: the tracker emulator did not start: no pty)"
    assert "1-minute load average 1.00 to 1.00" in trackers.machine_noise([failed])
    trackers.plot([failed], tmp_path / "trackers.png")
    assert (tmp_path / "trackers.png").exists()

