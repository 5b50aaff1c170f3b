"""Recording a tracker: `record_tracker(spec, duration, out)` writes its samples as they arrive.

The folder gets `tracker.csv` (the one tracker sample format, `predictors.SAMPLE_COLUMNS`, what
`rig bench predictors --trace` and `rig tune --trace` read), `tracker_device.csv` (row for row
beside it: what the device said besides the pose, its own time, record counter and angular rate)
and `tracker.json` (the device, its profile, the clock mapping with its uncertainty, the counters,
link events, and whether the run was interrupted). The tracker's reader thread queues samples as
they arrive, where a predictor's `poll()` would take them; the recording takes what is queued every
WRITE_INTERVAL_S and flushes it, so a crash of the process loses at most that much, and the
recording costs one wake-up per interval rather than one per sample (at 1000 Hz the wake-ups
would cost more CPU than the samples). Ctrl-C ends the recording cleanly: the reader is stopped,
what it had queued is written, the sidecar too, and the interrupt goes on to the caller.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from predictors import SAMPLE_COLUMNS
from rig.clock import MonotonicClock
from rig.devices.registry import make_tracker
from rig.devices.trackers.stream import RecordSource, TrackerRecord
from rig.errors import RigError
from rig.writers import CsvRecord

TRACKER_FILE = "tracker.csv"
DEVICE_FILE = "tracker_device.csv"
SIDECAR_FILE = "tracker.json"
DEVICE_COLUMNS = ("t_arrival", "device_time", "seq", "wx", "wy", "wz")
WRITE_INTERVAL_S = 0.02


@dataclass(frozen=True)
class TrackerRecording:
    """What a recording wrote: its folder, how many samples, and the sidecar's content."""

    out_dir: Path
    samples: int
    sidecar: dict[str, Any]


def _queued(tracker: Any) -> list[TrackerRecord]:
    if isinstance(tracker, RecordSource):
        return tracker.poll_records()
    return [TrackerRecord.of_sample(sample) for sample in tracker.poll()]


def record_tracker(
    spec: str,
    duration_s: float | None,
    out_dir: Path,
    *,
    overwrite: bool = False,
    progress: Callable[[float, float], None] = lambda done, total: None,
    on_batch: Callable[[list[TrackerRecord]], None] = lambda records: None,
    clock: MonotonicClock | None = None,
    until: Callable[[], bool] = lambda: False,
) -> TrackerRecording:
    """Records the tracker `spec` for `duration_s` seconds (None: until interrupted) into `out_dir`,
    on `clock` (a new MonotonicClock by default), or until `until()` says to end sooner (asked at
    every write).

    `on_batch(records)` sees every batch as it is written.
    """
    tracker = make_tracker(spec)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise RigError(f"cannot create {out_dir}: {error.strerror}") from None
    clock = clock or MonotonicClock()
    end = math.inf if duration_s is None else duration_s
    samples = 0
    interrupted = True
    with (
        CsvRecord(out_dir / TRACKER_FILE, SAMPLE_COLUMNS, overwrite=overwrite, flush_each_row=False) as sample_csv,
        CsvRecord(out_dir / DEVICE_FILE, DEVICE_COLUMNS, overwrite=overwrite, flush_each_row=False) as device_csv,
    ):

        def write(records: list[TrackerRecord]) -> None:
            sample_csv.write_numbers([record.sample_row() for record in records])
            device_csv.write_numbers(
                [(r.t_arrival, r.device_time, r.seq, *(r.angular_rate or (None, None, None))) for r in records]
            )
            sample_csv.flush()
            device_csv.flush()

        tracker.connect(clock)
        try:
            while (now := clock.now()) < end and not until():
                clock.wait_until(min(now + WRITE_INTERVAL_S, end))
                records = _queued(tracker)
                if records:
                    write(records)
                    samples += len(records)
                    on_batch(records)
                progress(min(clock.now(), end), end)
            interrupted = False
        finally:
            tracker.close()
            left = tracker.take_queued() if isinstance(tracker, RecordSource) else []
            write(left)
            samples += len(left)
            sidecar = {
                "spec": spec,
                "duration_s": clock.now(),
                "partial": interrupted,
                "samples": samples,
                "files": {"samples": TRACKER_FILE, "device": DEVICE_FILE},
                **tracker.report(),
            }
            (out_dir / SIDECAR_FILE).write_text(json.dumps(sidecar, indent=1) + "\n", encoding="utf-8")
    return TrackerRecording(out_dir, samples, sidecar)
