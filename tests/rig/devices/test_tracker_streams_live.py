"""Real tracker sources fed by the emulators through a pseudo-terminal, a TCP socket and LSL, on the
real clock: every intact record arrives once, in order; damage is counted, never let through; a
disconnect leaves a gap and the source reconnects. Only counts and order are asserted (no speeds)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from predictors import read_samples, read_trace
from rig.devices.trackers.clock_mapping import WINDOW_S
from rig.emulate import EmulatorConfig, quiet_tracker
from rig.service.tracker_recording import DEVICE_FILE, TRACKER_FILE, record_tracker
from rig.sim.fault_plan import parse_faults

RATE_HZ = 400.0
DURATION_S = 1.5
# The emulator waits for its reader, sends, then lingers: the recording outlasts it by this much.
MARGIN_S = 2.5


def _device_seq(folder: Path) -> list[int]:
    """The record counters of a recording, in file order."""
    lines = (folder / DEVICE_FILE).read_text().splitlines()[1:]
    return [int(line.split(",")[2]) for line in lines]


@pytest.mark.parametrize("transport, profile", [("pty", "binary-pose"), ("tcp", "binary-pose"), ("pty", "csv")])
def test_a_clean_serial_stream_is_recorded_whole_and_in_order(tmp_path: Path, emulated_tracker, transport: str, profile: str) -> None:
    address = str(tmp_path / "tracker") if transport == "pty" else "0"
    config = EmulatorConfig(transport, address, quiet_tracker(RATE_HZ), DURATION_S, profile, log=tmp_path / "sent.csv")
    with emulated_tracker(config) as emulator:
        recording = record_tracker(emulator.spec, DURATION_S + MARGIN_S, tmp_path / "out")
    sent = emulator.fates()
    assert len(sent["intact"]) == int(RATE_HZ * DURATION_S)
    samples = read_samples(tmp_path / "out" / TRACKER_FILE)
    assert recording.samples == len(samples) == len(sent["intact"])
    assert recording.sidecar["counters"]["corrupt"] == 0
    arrivals = np.array([s.t_arrival for s in samples])
    assert np.all(np.diff(arrivals) >= 0.0)
    device = np.array([float(line.split(",")[1]) for line in (tmp_path / "out" / DEVICE_FILE).read_text().splitlines()[1:]])
    sensor = np.array([s.t_sensor for s in samples])
    # Once the mapping has its first window, the device's clock mapped onto the rig's keeps the
    # device's own spacing, to within the jitter the envelope leaves (on a loaded machine: 1 ms).
    settled = arrivals[1:] > arrivals[0] + WINDOW_S
    assert np.max(np.abs(np.diff(sensor) - np.diff(device))[settled]) < 1e-3
    assert np.all(arrivals - sensor >= 0.0)


@pytest.mark.parametrize("transport", ["pty", "tcp"])
def test_the_emulator_ends_when_its_reader_hangs_up_and_sends_what_the_default_recorder_reads(
    tmp_path: Path, emulated_tracker, transport: str
) -> None:
    address = str(tmp_path / "tracker") if transport == "pty" else "0"
    sending_s = 20.0  # far longer than the recording: the emulator ends early only if it sees the reader go
    config = EmulatorConfig(transport, address, quiet_tracker(RATE_HZ), sending_s, log=tmp_path / "sent.csv")
    with emulated_tracker(config) as emulator:
        recording = record_tracker(f"serial:{emulator.sink.address}", DURATION_S + MARGIN_S, tmp_path / "out")
        assert emulator.join(timeout_s=sending_s / 2), "the emulator was still sending once its reader had gone"
    assert emulator.events[-1] == "the reader went away; stopping"
    assert 0 < recording.samples <= emulator.counts.intact < RATE_HZ * sending_s
    assert recording.sidecar["counters"]["corrupt"] == 0, "the recorder's default profile reads the emulator's default records"


def test_corrupt_bytes_and_a_disconnect_lose_no_intact_record_and_fabricate_none(tmp_path: Path, emulated_tracker) -> None:
    faults = parse_faults("corrupt=0.01,garbage=20,disconnect=0.7:0.3")
    config = EmulatorConfig("pty", str(tmp_path / "tracker"), quiet_tracker(RATE_HZ), DURATION_S, "binary-pose", faults=faults, seed=3,
                            log=tmp_path / "sent.csv")  # fmt: skip
    with emulated_tracker(config) as emulator:
        recording = record_tracker(emulator.spec, DURATION_S + MARGIN_S, tmp_path / "out")
    sent = emulator.fates()
    recorded = _device_seq(tmp_path / "out")
    assert sent["damaged"] and sent["lost"], "the faults must have happened for the test to mean anything"
    assert recorded == sorted(sent["intact"])
    counters = recording.sidecar["counters"]
    # Garbage between records counts as damage too, so corrupt may exceed what the emulator damaged;
    # the counter's gaps not taken up by damage are the records lost while the port was away.
    assert counters["corrupt"] >= len(sent["damaged"])
    assert counters["dropped"] <= len(sent["lost"]) <= counters["dropped"] + counters["corrupt"] - len(sent["damaged"])
    assert counters["reconnects"] == 1
    assert [e["what"] for e in recording.sidecar["events"]][:3] == ["lost", "restored", "gap"]


def test_an_lsl_stream_is_recorded_whole_with_its_latency_known(tmp_path: Path, emulated_tracker) -> None:
    config = EmulatorConfig("lsl", f"rig-test-{tmp_path.name}", quiet_tracker(RATE_HZ), DURATION_S, log=tmp_path / "sent.csv")
    with emulated_tracker(config) as emulator:
        recording = record_tracker(emulator.spec, DURATION_S + MARGIN_S, tmp_path / "out")
    assert recording.samples == len(emulator.fates()["intact"]) == int(RATE_HZ * DURATION_S)
    latency = recording.sidecar["latency"]
    assert latency["samples"] == recording.samples and latency["median_ms"] >= 0.0
    assert recording.sidecar["clock_mapping"]["kind"] == "round-trip"
    trace = read_trace(tmp_path / "out" / TRACKER_FILE)
    assert np.all(trace.t_arrival - trace.t > -1e-3), "a sample cannot arrive before it was measured"
