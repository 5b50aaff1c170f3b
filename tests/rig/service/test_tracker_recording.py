"""A tracker recording writes what its source says: the device's own time, counter and rate where
the source hands out whole records (any `RecordSource`, not only the rig's own streams), the pose
samples alone where it does not."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from predictors import PoseSample
from rig.clock import Clock, VirtualClock
from rig.devices.trackers.stream import TrackerRecord
from rig.service import tracker_recording
from rig.service.tracker_recording import DEVICE_FILE, TRACKER_FILE, record_tracker

RATE_HZ = 100.0


class SamplesOnly:
    """A third-party tracker that gives pose samples and nothing else: one every 10 ms."""

    def __init__(self) -> None:
        self._clock: Clock | None = None
        self._sent = 0

    def connect(self, clock: Clock) -> None:
        self._clock = clock

    def _due(self) -> list[PoseSample]:
        assert self._clock is not None
        due = int(self._clock.now() * RATE_HZ)
        samples = [
            PoseSample(k / RATE_HZ, k / RATE_HZ + 0.002, np.array([k * 1e-3, 0.0, 0.0]), np.array([1.0, 0.0, 0.0, 0.0]))
            for k in range(self._sent, due)
        ]
        self._sent = max(self._sent, due)
        return samples

    def poll(self) -> list[PoseSample]:
        return self._due()

    def wait(self, timeout_s: float) -> list[PoseSample]:
        return self._due()

    def fault(self) -> None:
        return None

    def report(self) -> dict[str, Any]:
        return {"sent": self._sent}

    def close(self) -> None:
        pass


class WithRecords(SamplesOnly):
    """The same tracker, also handing out its records with its own clock (1000 s ahead) and counter."""

    def _records(self) -> list[TrackerRecord]:
        return [
            TrackerRecord.of_sample(sample)._replace(device_time=1000.0 + sample.t_sensor, seq=round(sample.t_sensor * RATE_HZ))
            for sample in self._due()
        ]

    def poll_records(self) -> list[TrackerRecord]:
        return self._records()

    def wait_records(self, timeout_s: float) -> list[TrackerRecord]:
        return self._records()

    def take_queued(self) -> list[TrackerRecord]:
        return self._records()


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as file:
        return list(csv.DictReader(file))


@pytest.mark.parametrize("source", [SamplesOnly, WithRecords])
def test_a_recording_keeps_every_sample_and_the_device_columns_its_source_has(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, source: type[SamplesOnly]
) -> None:
    monkeypatch.setattr(tracker_recording, "make_tracker", lambda spec: source())
    recording = record_tracker("third-party:any", 0.5, tmp_path, clock=VirtualClock())
    samples, device = _rows(tmp_path / TRACKER_FILE), _rows(tmp_path / DEVICE_FILE)
    assert recording.samples == len(samples) == len(device) == 50
    assert [float(row["t_sensor"]) for row in samples] == pytest.approx([k / RATE_HZ for k in range(50)])
    if source is WithRecords:
        assert [float(row["device_time"]) for row in device] == pytest.approx([1000.0 + k / RATE_HZ for k in range(50)])
        assert [int(row["seq"]) for row in device] == list(range(50))
    else:
        assert all(row["device_time"] == "" and row["seq"] == "" for row in device)
    assert recording.sidecar["sent"] == 50 and not recording.sidecar["partial"]
