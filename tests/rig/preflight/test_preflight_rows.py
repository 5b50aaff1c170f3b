"""The pre-flight check's verdicts on known inputs: a tracker's rate, jitter and clock offset from
samples on a virtual clock, the disk's room against a film's size, the overall status and the exit
status it gives, and the table a lab reads."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from predictors import PoseSample
from rig.clock import VirtualClock
from rig.cli import EXIT_UNTRUSTED
from rig.commands.check import exit_status, table
from rig.preflight import CheckReport
from rig.preflight import disk as disk_check
from rig.preflight.rows import FAIL, PASS, WARN, CheckRow, graded, worst
from rig.preflight.tracker import JITTER_WARN_MS, TrackerProbe


class SteadyTracker:
    """A tracker measuring at `rate_hz` on the device's clock, each sample arriving after `delays[k %
    len(delays)]` seconds, on a virtual clock; its report maps the device's clock one way."""

    def __init__(self, rate_hz: float, delays: list[float], offset_uncertainty_s: float = 1e-5) -> None:
        self.rate_hz = rate_hz
        self.delays = delays
        self.uncertainty = offset_uncertainty_s
        self.clock: VirtualClock | None = None
        self.k = 0
        self.closed = False

    def connect(self, clock: VirtualClock) -> None:
        self.clock = clock

    def _arrival(self, k: int) -> float:
        return k / self.rate_hz + self.delays[k % len(self.delays)]

    def wait(self, timeout_s: float) -> list[PoseSample]:
        end = self.clock.now() + timeout_s
        arrival = self._arrival(self.k)
        if arrival > end:
            self.clock.wait_until(end)
            return []
        self.clock.wait_until(max(arrival, self.clock.now()))
        sample = PoseSample(self.k / self.rate_hz, arrival, np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
        self.k += 1
        return [sample]

    def report(self) -> dict[str, Any]:
        return {
            "counters": {"received": self.k, "corrupt": 0, "rejected": 0},
            "clock_mapping": {"kind": "one-way", "offset_s": 2.0, "offset_interval_s": [2.0, 2.0 + self.uncertainty]},
        }

    def close(self) -> None:
        self.closed = True


def _probe_rows(tracker: SteadyTracker, seconds: float = 2.0) -> dict[str, CheckRow]:
    probe = TrackerProbe("steady", tracker)
    probe.run(VirtualClock(), seconds)
    assert tracker.closed
    return {row.what: row for row in probe.rows(seconds)}


def test_a_steady_tracker_passes_with_its_rate_and_offset_measured() -> None:
    rows = _probe_rows(SteadyTracker(250.0, [0.001]))
    assert rows["rate"].status == PASS and rows["rate"].values["rate_hz"] == pytest.approx(250.0, rel=1e-9)
    assert rows["jitter"].status == PASS and rows["jitter"].values["jitter_ms"] == pytest.approx(0.0, abs=1e-6)
    assert rows["clock offset"].status == PASS and rows["clock offset"].values["offset_uncertainty_ms"] == pytest.approx(0.01)


def test_arrivals_alternately_late_by_d_have_a_jitter_of_d() -> None:
    spread_s = 2 * (JITTER_WARN_MS + 1.0) * 1e-3  # intervals alternate period -+ spread: sd = spread
    rows = _probe_rows(SteadyTracker(100.0, [0.0, spread_s]))
    assert rows["jitter"].values["jitter_ms"] == pytest.approx(spread_s * 1e3, rel=0.01)
    assert rows["jitter"].status == WARN and rows["jitter"].fix
    assert rows["rate"].status == PASS


def test_a_slow_tracker_and_a_poorly_known_offset_warn() -> None:
    rows = _probe_rows(SteadyTracker(30.0, [0.001], offset_uncertainty_s=0.01))
    assert rows["rate"].status == WARN and "faster" in rows["rate"].fix
    assert rows["clock offset"].status == WARN


def test_a_tracker_that_sends_nothing_fails() -> None:
    rows = _probe_rows(SteadyTracker(100.0, [10.0]), seconds=1.0)
    assert list(rows) == ["samples"] and rows["samples"].status == FAIL and "0 samples in 1 s" in rows["samples"].measured


@pytest.fixture
def free_bytes(monkeypatch: pytest.MonkeyPatch) -> Any:
    """Sets the free room the disk check sees."""

    def set_free(free: int) -> None:
        monkeypatch.setattr(disk_check.shutil, "disk_usage", lambda folder: SimpleNamespace(free=free))

    return set_free


@pytest.mark.parametrize("free, status", [(10**12, PASS), (int(1.5 * 1.25 * 3.6e9), WARN), (int(0.9 * 1.25 * 3.6e9), FAIL)])
def test_the_disk_must_hold_the_film_with_its_margin(tmp_path: Path, free_bytes: Any, free: int, status: str) -> None:
    free_bytes(free)
    row = disk_check.check_disk(tmp_path, fps=120.0, frame_bytes=500_000, duration_s=60.0)  # 3.6 GB of film
    assert row.status == status and row.values["needed_bytes"] == pytest.approx(1.25 * 3.6e9)


def test_a_run_without_a_camera_needs_no_room_for_a_film(tmp_path: Path, free_bytes: Any) -> None:
    free_bytes(0)
    assert disk_check.check_disk(tmp_path, None, None, 60.0).status == PASS


def test_the_worst_row_decides_and_the_exit_status_follows() -> None:
    rows = [CheckRow("a", "x", PASS, "fine"), CheckRow("b", "y", WARN, "meh", "do this")]
    assert worst(rows) == WARN and exit_status(WARN) == 3
    assert worst([*rows, CheckRow("c", "z", FAIL, "no", "fix that")]) == FAIL and exit_status(FAIL) == EXIT_UNTRUSTED
    assert worst([]) == PASS and exit_status(PASS) == 0
    assert [graded(v, 0.95, 0.5) for v in (1.0, 0.95, 0.7, 0.49)] == [PASS, PASS, WARN, FAIL]
    with pytest.raises(ValueError, match="status"):
        CheckRow("a", "x", "fine", "fine")


def test_the_table_gives_each_check_a_line_and_a_fix_under_each_that_did_not_pass() -> None:
    report = CheckReport([CheckRow("display", "refresh", PASS, "60.00 Hz"), CheckRow("tracker", "jitter", WARN, "sd 3 ms", "use USB")], 4.25)
    assert table(report).splitlines() == [
        "PASS  display  refresh  60.00 Hz",
        "WARN  tracker  jitter   sd 3 ms",
        "                        fix: use USB",
        "overall: warn (1 pass, 1 warn, 0 fail) in 4.2 s",
    ]
    assert report.to_dict()["status"] == WARN and report.to_dict()["checks"][1]["fix"] == "use USB"
