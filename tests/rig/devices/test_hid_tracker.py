"""The HID tracker against a faithful fake of hidapi's device object, replaying byte-exact reports
from a transcript (tests/rig/devices/transcripts): the fake answers `read(max_length, timeout_ms)`
with one report as a list of byte values, an empty list when none is due, and raises OSError as
hidapi does when the device is unplugged. Every report of a transcript must be read."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from rig.clock import MonotonicClock
from rig.devices.trackers.hid_tracker import hid_tracker, parse_hid_address
from rig.errors import ConfigError, RigError

TRANSCRIPT = Path(__file__).parent / "transcripts" / "hid-quat16-turn.txt"
WAIT_LIMIT_S = 10.0


def reports(path: Path) -> list[list[int]]:
    return [list(bytes.fromhex(line)) for line in path.read_text().splitlines() if line and not line.startswith("#")]


class FakeHidDevice:
    """hid.device after open(): replays `reports`, then either times out forever or is unplugged."""

    def __init__(self, replay: list[list[int]], unplug_after: bool = False) -> None:
        self.replay = list(replay)
        self.unplug_after = unplug_after
        self.closed = False
        self.read_lengths: list[int] = []

    def read(self, max_length: int, timeout_ms: int = 0) -> list[int]:
        self.read_lengths.append(max_length)
        if self.replay:
            return self.replay.pop(0)[:max_length]
        if self.unplug_after:
            raise OSError("read error")
        return []

    def close(self) -> None:
        self.closed = True


def record_all(tracker, count: int) -> list:
    records, clock = [], MonotonicClock()
    while len(records) < count and clock.now() < WAIT_LIMIT_S:
        records += tracker.wait_records(0.05)
    return records


def test_the_transcript_decodes_to_the_turn_it_recorded_with_every_fault_counted() -> None:
    device = FakeHidDevice(reports(TRANSCRIPT))
    tracker = hid_tracker("1234:abcd", open_device=lambda vendor, product: device)
    tracker.connect(MonotonicClock())
    try:
        records = record_all(tracker, 12)
    finally:
        tracker.close()
    assert not device.replay and device.closed
    kept = [k for k in range(14) if k not in (5, 8)]
    assert len(records) == len(kept)
    for k, record in zip(kept, records):
        angle = math.radians(90.0) * k * 0.01
        assert record.device_time == pytest.approx(4294.967 + k * 0.01, abs=1e-6), "the microsecond counter wraps"
        np.testing.assert_allclose(record.sample.orientation, [math.cos(angle / 2), 0, 0, math.sin(angle / 2)], atol=1e-4)
        np.testing.assert_allclose(record.angular_rate, [0, 0, math.radians(90.0)], atol=math.radians(0.0625))
        np.testing.assert_array_equal(record.sample.position, [0.0, 0.0, 0.0])
    counters = tracker.report()["counters"]
    assert counters == {"received": 12, "corrupt": 1, "rejected": 0, "dropped": 2, "out_of_order": 0, "reconnects": 0}
    assert [r.seq for r in records][:2] == [65530, 65531] and records[-1].seq == (65530 + 14) % 65536


def test_an_unplugged_device_is_reopened_and_reading_goes_on() -> None:
    replay = reports(TRANSCRIPT)
    devices = [FakeHidDevice(replay[:4], unplug_after=True), FakeHidDevice(replay[9:])]
    opened = []

    def open_device(vendor: int, product: int) -> FakeHidDevice:
        opened.append((vendor, product))
        return devices[len(opened) - 1]

    tracker = hid_tracker("0x1234:0xABCD:hid-quat16", open_device=open_device)
    tracker.connect(MonotonicClock())
    try:
        records = record_all(tracker, 4 + 5)
    finally:
        tracker.close()
    assert opened == [(0x1234, 0xABCD)] * 2
    report = tracker.report()
    assert [r.seq for r in records] == [65530, 65531, 65532, 65533, 3, 4, 6, 7, 8]
    assert report["counters"]["reconnects"] == 1
    assert report["counters"]["dropped"] == 1 + 5, "the records missed while unplugged count as dropped"
    assert [e["what"] for e in report["events"]][:2] == ["lost", "restored"]


def test_a_device_that_cannot_be_opened_says_what_to_check() -> None:
    def refuse(vendor: int, product: int) -> FakeHidDevice:
        raise OSError("open failed")

    tracker = hid_tracker("1234:abcd", open_device=refuse)
    with pytest.raises(RigError, match="cannot open HID device 1234:abcd.*rig devices"):
        tracker.connect(MonotonicClock())


@pytest.mark.parametrize(
    "address, message",
    [("1234", "VID:PID"), ("12g4:abcd", "hex"), ("12345:abcd", "16-bit"), ("1234:abcd:binary-pose", "HID"), ("1234:abcd:nosuch", "no tracker profile")],
)
def test_bad_hid_specs_say_what_is_wrong(address: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        hid_tracker(address)


def test_ids_are_hex_with_or_without_0x() -> None:
    assert parse_hid_address("046d:C52B") == (0x046D, 0xC52B, "hid-quat16")
