"""The tracker's pre-flight check: its sample rate (by its own clock where its records carry their
time, else by arrival), the jitter of its arrivals, and how its clock maps onto the rig's (the
offset and its uncertainty, from the stream's clock mapping), from a few seconds of its samples."""

from __future__ import annotations

from typing import Any

import numpy as np

from rig.clock import Clock
from rig.devices.protocols import TrackerSource
from rig.devices.registry import make_tracker
from rig.devices.trackers.stream import RecordSource, TrackerRecord
from rig.errors import RigError
from rig.preflight.rows import PASS, WARN, CheckRow, failed

MIN_RATE_HZ = 60.0
"""A tracker slower than a 60 Hz display leaves frames with no new sample: each pose is extrapolated further."""
JITTER_WARN_MS = 2.0
"""Arrival intervals spread wider than this (standard deviation) widen every latency figure's spread."""
DAMAGED_WARN = 0.01
"""More than this share of records damaged or refused: the profile or the baud rate is likely wrong."""
OFFSET_WARN_MS = 5.0
"""A clock offset known no better than this (its interval's width) blurs the tracker's latency."""


class TrackerProbe:
    """Listens to the tracker `spec` (made from it unless `tracker` is given) on a thread of its own
    (the caller's `run`) and turns what came into rows (`rows`)."""

    def __init__(self, spec: str, tracker: TrackerSource | None = None) -> None:
        self.spec = spec
        self._tracker = tracker if tracker is not None else make_tracker(spec)
        self._arrivals: list[float] = []
        self._device: list[float | None] = []
        self._report: dict[str, Any] = {}
        self._error: BaseException | None = None

    def run(self, clock: Clock, seconds: float) -> None:
        """Connect, take every sample for `seconds` from then, and close."""
        try:
            self._tracker.connect(clock)
            until = clock.now() + seconds
            try:
                while (left := until - clock.now()) > 0:
                    for record in self._wait(left):
                        self._arrivals.append(record.t_arrival)
                        self._device.append(record.device_time)
                self._report = self._tracker.report()
            finally:
                self._tracker.close()
        except BaseException as error:  # noqa: BLE001 - handed to the caller's thread by `rows`
            self._error = error

    def _wait(self, timeout_s: float) -> list[TrackerRecord]:
        """The records that came within `timeout_s`, with the device's own time where the source has it."""
        if isinstance(self._tracker, RecordSource):
            return self._tracker.wait_records(timeout_s)
        return [TrackerRecord.of_sample(sample) for sample in self._tracker.wait(timeout_s)]

    def rows(self, seconds: float) -> list[CheckRow]:
        """What the samples say; a tracker that would not connect is a failed row (any other error
        is the rig's own, raised here)."""
        if self._error is not None and not isinstance(self._error, RigError):
            raise self._error
        if self._error is not None:
            return [failed("tracker", "samples", str(self._error), "check the tracker's spec, cable and power (`rig devices` lists what it sees)")]
        if len(self._arrivals) < 3:
            return [failed("tracker", "samples", f"{len(self._arrivals)} samples in {seconds:g} s from {self.spec}",
                           "is the tracker on and streaming, and does the profile match its records? `rig record-tracker` "
                           "shows its link counters")]  # fmt: skip
        return [self._rate_row(), self._jitter_row(), self._clock_row()]

    def _rate_row(self) -> CheckRow:
        device = np.array([t for t in self._device if t is not None])
        by_device = device.size == len(self._arrivals) and device[-1] > device[0]
        times = device if by_device else np.array(self._arrivals)
        rate = (times.size - 1) / (times[-1] - times[0]) if times[-1] > times[0] else float("inf")
        counters = self._report.get("counters", {})
        received = max(int(counters.get("received") or 0), times.size)
        bad = int(counters.get("corrupt") or 0) + int(counters.get("rejected") or 0)
        clock = "by its own clock" if by_device else "by arrival"
        values = {"rate_hz": rate, "by": clock, "samples": int(times.size), "damaged_or_refused": bad}
        measured = f"{rate:.1f} Hz {clock} ({times.size} samples; {bad} records damaged or refused)"
        if bad > DAMAGED_WARN * received:
            return CheckRow("tracker", "rate", WARN, measured, "many damaged records: check the profile and the baud rate", values)
        if rate < MIN_RATE_HZ:
            return CheckRow("tracker", "rate", WARN, measured,
                            f"slower than {MIN_RATE_HZ:g} Hz: set the tracker to send faster (each frame's pose is extrapolated further)",
                            values)  # fmt: skip
        return CheckRow("tracker", "rate", PASS, measured, values=values)

    def _jitter_row(self) -> CheckRow:
        intervals = np.diff(np.array(self._arrivals))
        jitter_ms = float(np.std(intervals)) * 1e3
        longest_ms = float(np.max(intervals)) * 1e3
        values = {"jitter_ms": jitter_ms, "longest_gap_ms": longest_ms}
        measured = f"arrival intervals: sd {jitter_ms:.2f} ms, longest {longest_ms:.1f} ms"
        if jitter_ms > JITTER_WARN_MS:
            return CheckRow("tracker", "jitter", WARN, measured,
                            "samples arrive irregularly: give the tracker a USB port of its own, close programs loading the CPU",
                            values)  # fmt: skip
        return CheckRow("tracker", "jitter", PASS, measured, values=values)

    def _clock_row(self) -> CheckRow:
        mapping = self._report.get("clock_mapping", {})
        if mapping.get("kind") == "arrival":
            return CheckRow("tracker", "clock offset", WARN, "the tracker sends no time of its own (sensor time = arrival)",
                            "its transport delay hides in the latency: use a profile with its time field if it sends one",
                            {"kind": mapping.get("kind")})  # fmt: skip
        if mapping.get("offset_s") is None:
            return CheckRow("tracker", "clock offset", WARN, f"not measured yet ({mapping.get('kind')}): too few samples",
                            "the tracker started streaming late in the check: run the check again", {"kind": mapping.get("kind")})  # fmt: skip
        low, high = mapping["offset_interval_s"]
        width_ms = (high - low) * 1e3
        values = {"kind": mapping["kind"], "offset_s": mapping["offset_s"], "offset_uncertainty_ms": width_ms, "drift_ppm": mapping.get("drift_ppm")}
        measured = f"device - rig {mapping['offset_s']:.6f} s, known to {width_ms:.3f} ms ({mapping['kind']})"
        if width_ms > OFFSET_WARN_MS:
            return CheckRow("tracker", "clock offset", WARN, measured, "the offset is poorly known: check the device's time field and its unit", values)
        return CheckRow("tracker", "clock offset", PASS, measured, values=values)
