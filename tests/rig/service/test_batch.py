"""Batches: one row per video, failures as rows, the summary on disk as rows come, the same answer
on any executor."""

from __future__ import annotations

import csv
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rig.errors import ConfigError
from rig.service.analyse import AnalysisRequest
from rig.service.batch import SUMMARY_COLUMNS, BatchItem, BatchRun, find_videos, run_batch


def rows_of(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as stream:
        return list(csv.DictReader(stream))


def test_folders_and_globs_name_videos_and_a_folder_of_images_is_one(tmp_path: Path) -> None:
    (tmp_path / "a").mkdir()
    for name in ("b.avi", "a.mp4", "notes.txt"):
        (tmp_path / "a" / name).write_text("")
    (tmp_path / "frames").mkdir()
    (tmp_path / "frames" / "0001.png").write_text("")
    found = find_videos([tmp_path / "a", str(tmp_path / "*" / "b.avi"), tmp_path / "frames"])
    assert found == [tmp_path / "a" / "a.mp4", tmp_path / "a" / "b.avi", tmp_path / "frames"]
    with pytest.raises(ConfigError, match="nothing matches"):
        find_videos([str(tmp_path / "*.mkv")])


def test_a_bad_video_is_a_failed_row_and_the_batch_goes_on(small_runs, tmp_path: Path) -> None:
    items = [BatchItem(AnalysisRequest(small_runs[name]), {"speed": name}) for name in ("fast", "broken", "slow")]
    rows = run_batch(items, tmp_path / "summary.csv")
    assert rows[0]["status"] in ("ok", "warning") and rows[2]["status"] in ("ok", "warning")
    assert rows[1]["status"] == "failed"
    assert rows[1]["latency_ms"] is None and "video" in rows[1]["error"]
    assert all(row["latency_ms"] > 0 for row in (rows[0], rows[2]))
    on_disk = rows_of(tmp_path / "summary.csv")
    assert [row["video"] for row in on_disk] == [str(small_runs[n]) for n in ("fast", "broken", "slow")]
    assert list(on_disk[0]) == [*SUMMARY_COLUMNS, "speed"]
    record = json.loads((tmp_path / "summary.json").read_text())
    assert record["partial"] is False and len(record["rows"]) == 3


def test_rows_reach_the_disk_as_they_come_and_the_end_puts_them_in_input_order(tmp_path: Path) -> None:
    run = BatchRun(tmp_path / "s.csv", ("index", "video", "status"))
    run.open()
    run.add({"index": 1, "video": "b", "status": "ok"})
    assert [row["video"] for row in rows_of(tmp_path / "s.csv")] == ["b"]
    assert json.loads((tmp_path / "s.json").read_text())["partial"] is True
    run.add({"index": 0, "video": "a", "status": "failed"})
    run.finish()
    assert [row["video"] for row in rows_of(tmp_path / "s.csv")] == ["a", "b"]
    assert json.loads((tmp_path / "s.json").read_text())["partial"] is False


def test_two_local_workers_give_the_serial_summary_row_for_row(small_runs, tmp_path: Path) -> None:
    items = [BatchItem(AnalysisRequest(small_runs[name])) for name in ("fast", "broken", "slow")]
    serial = run_batch(items, tmp_path / "serial.csv")
    parallel = run_batch(items, tmp_path / "parallel.csv", workers=2)
    keep = ("video", "status", "latency_ms", "ci95_low_ms", "ci95_high_ms", "error")
    assert [{k: r[k] for k in keep} for r in parallel] == [{k: r[k] for k in keep} for r in serial]


def _wait_until_listening(port: int, process: subprocess.Popen, patience_s: float = 60.0) -> None:
    """A lab's scheduler is up before a batch is sent to it; this one may take a while to start on
    a loaded machine."""
    deadline = time.monotonic() + patience_s
    while time.monotonic() < deadline and process.poll() is None:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
            return
        except OSError:
            time.sleep(0.2)
    pytest.fail(f"the Dask scheduler did not listen on port {port} within {patience_s:.0f} s")


def test_a_batch_on_an_existing_scheduler_gives_the_serial_summary(small_runs, tmp_path: Path) -> None:
    """A Dask scheduler and a worker started as separate processes, as on a lab's cluster."""
    port = 8700 + os.getpid() % 200
    address = f"tcp://127.0.0.1:{port}"
    bin_dir = Path(sys.executable).parent
    scheduler = subprocess.Popen([bin_dir / "dask", "scheduler", "--port", str(port), "--dashboard-address", ":0", "--no-show"],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    worker = subprocess.Popen([bin_dir / "dask", "worker", address, "--nthreads", "1", "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        _wait_until_listening(port, scheduler)
        items = [BatchItem(AnalysisRequest(small_runs[name])) for name in ("slow", "broken")]
        remote = run_batch(items, tmp_path / "remote.csv", scheduler=address)
        serial = run_batch(items, tmp_path / "serial.csv")
        assert [(r["status"], r["latency_ms"]) for r in remote] == [(r["status"], r["latency_ms"]) for r in serial]
    finally:
        for process in (worker, scheduler):
            process.send_signal(signal.SIGINT)
        for process in (worker, scheduler):
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                process.kill()
