"""Hardware in the loop, on an emulated AVR: the real firmware ELF runs on simavr and the real
Python link talks to it through a pseudo-terminal; the board's reports are checked against the
scripted pendulum and display it sees."""

from __future__ import annotations

import argparse
import json
import math
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import serial

from analysis.board.blink_code import BlinkSchedule
from analysis.board.recording import load_table
from rig.board import BoardIdentity, BoardRecorder, LedChange, LinkChange, Microcontroller
from rig.board.framing import FrameDecoder, encode_frame
import predictors
from rig.board.instrument import BoardInstrument, BoardSettings
from rig.clock import MonotonicClock
from rig.devices.protocols import Instrument
from rig.lsl import ExternalRenderer
from rig.render.protocol import RenderSetup
from rig.session import MeasuredCost, OneImagePerAppFrame, RunRecord, Session, SessionParts
from rig.sim.display import DisplayConfig, SimDisplay
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import SimTracker, TrackerConfig
from rig.board.protocol import protocol
from rig.commands.board import add_parser
from rig.errors import RigError

RISE, FALL = 512, 256
# Board seconds to record: the emulator keeps to the wall clock unless the machine is too busy,
# so waits are for the board's clock, up to a generous wall-clock limit.
RECORD_S = 7.0
WALL_LIMIT_S = 60.0
# How long before its time stamp an edge happened, at least and at most: the board stamps it in
# its interrupt handler a few microseconds later (more when another handler runs), on a clock
# started within a microsecond of reset.
EDGE_BEFORE_STAMP_S = (-1e-6, 30e-6)


def run_cli(*argv: str) -> int:
    parser = argparse.ArgumentParser(prog="rig")
    add_parser(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(list(argv))
    return args.func(args)


def wait_until(condition, timeout: float, what: str) -> None:
    """Polls `condition` until it holds; fails after `timeout` seconds."""
    deadline = time.monotonic() + timeout
    pause = threading.Event()
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s waiting for {what}")
        pause.wait(0.02)


def check_edges_follow_script(encoder: dict[str, np.ndarray], world) -> None:
    """Each edge went from count - step to count at its time, as the script drives the pins (the
    board counts from 0 at reset)."""
    t = encoder["board_time_s"]
    zero = world.count(0.0)
    np.testing.assert_array_equal(world.count(t - EDGE_BEFORE_STAMP_S[0]) - zero, encoder["count"])
    np.testing.assert_array_equal(world.count(t - EDGE_BEFORE_STAMP_S[1]) - zero, encoder["count"] - encoder["step"])


def scripted_crossings(world, start: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """Threshold crossings of the noise-free signal with the RISE/FALL hysteresis: times, rising."""
    t = np.arange(start, end, 2e-6)
    signal = world.adc_counts(t)
    times, rising, high = [], [], signal[0] >= RISE
    for level, up in ((RISE, True), (FALL, False)):
        crossed = np.flatnonzero((signal[:-1] < level) != (signal[1:] < level))
        for i in crossed:
            goes_up = signal[i + 1] > signal[i]
            if goes_up == up:
                fraction = (level - signal[i]) / (signal[i + 1] - signal[i])
                times.append(t[i] + fraction * (t[i + 1] - t[i]))
                rising.append(up)
    order = np.argsort(times)
    times, rising = np.array(times)[order], np.array(rising)[order]
    # Keep the alternation the hysteresis allows.
    keep, state = [], high
    for k, up in enumerate(rising):
        if up != state:
            keep.append(k)
            state = up
    return times[keep], rising[keep]


@pytest.fixture(scope="module")
def recording(board, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """RECORD_S board seconds of encoder and photodiode events."""
    out = tmp_path_factory.mktemp("recording") / "run"
    recorder = BoardRecorder(out)
    try:
        with Microcontroller(board.url, resync_every_s=2.0) as link:
            link.add_listener(recorder)
            link.configure_encoder(0)
            link.configure_photodiode(RISE, FALL)
            start = link.status().board_time
            link.stream(encoder=True, photodiode=True)
            link.wait_for_board_time(start + RECORD_S, WALL_LIMIT_S)
            link.stream()
    finally:
        recorder.close()
    return out


def test_board_identifies_itself(board) -> None:
    spec = protocol()
    with Microcontroller(board.url) as link:
        status = link.status()
    assert link.identity == BoardIdentity(
        name=spec.strings["RIG_BOARD_NAME"],
        protocol=spec["RIG_PROTOCOL_VERSION"],
        firmware=f"{spec['RIG_FIRMWARE_VERSION_MAJOR']}.{spec['RIG_FIRMWARE_VERSION_MINOR']}.{spec['RIG_FIRMWARE_VERSION_PATCH']}",
        tick_hz=spec["RIG_TICK_HZ"],
        cpu_hz=16_000_000,
    )
    assert (status.rx_corrupt, status.rx_unknown, status.tx_dropped, status.event_overflow, status.quad_invalid) == (0, 0, 0, 0, 0)


def test_clock_sync_interval_is_narrower_than_100_us(board) -> None:
    start_line = next(line for line in board.lines if "emulated time 0 is CLOCK_MONOTONIC" in line)
    start = float(start_line.split()[-2])
    with Microcontroller(board.url, sync_round_trips=128) as link:
        intervals = [link.sync() for _ in range(3)]
    # Two of three: a machine busy enough to stall the emulator in the middle of a measurement
    # makes that one wider.
    assert np.median([interval.width for interval in intervals]) < 100e-6
    for interval in intervals:
        # Board time is the monotonic clock since the emulator started, less the time the
        # emulator stood still when the machine was busy (so the offset is at most -start).
        assert interval.low < -start + 1e-3


def test_raw_link_counts_and_skips_bad_frames(board) -> None:
    spec = protocol()
    decoder = FrameDecoder(spec)
    replies: dict[int, dict] = {}
    with serial.serial_for_url(board.url, timeout=0.05) as port:

        def answered(seq: int) -> bool:
            for frame in decoder.feed(port.read(4096)):
                fields = spec.layout(frame.type).unpack(frame.payload)
                if not fields.get("unsolicited") and "reply_to" in fields:
                    replies[fields["reply_to"]] = fields
            return seq in replies

        port.reset_input_buffer()
        port.write(encode_frame(spec["RIG_CMD_STATUS"], 9, b"", spec))
        wait_until(lambda: answered(9), 5.0, "the board's status")
        port.write(b"\x13\x37garbage\x00")  # fails COBS
        port.write(b"\x02\x80\x00")  # one byte inside: too short for header and CRC
        port.write(encode_frame(0x7F, 1, b"", spec))  # CRC good, type unknown
        bad = spec.layout(spec["RIG_CMD_PHOTODIODE"]).pack(rise=100, fall=200, raw_every=0)
        port.write(encode_frame(spec["RIG_CMD_PHOTODIODE"], 2, bad, spec))
        port.write(encode_frame(spec["RIG_CMD_STATUS"], 3, b"", spec))
        wait_until(lambda: answered(3), 5.0, "the board's answers")
    assert replies[1]["status"] == spec["RIG_STATUS_UNKNOWN_COMMAND"]
    assert replies[2]["status"] == spec["RIG_STATUS_BAD_VALUE"]
    assert replies[3]["rx_corrupt"] - replies[9]["rx_corrupt"] == 2
    assert replies[3]["rx_unknown"] - replies[9]["rx_unknown"] == 1
    assert replies[3]["rx_frames"] - replies[9]["rx_frames"] == 3


def test_record_command_writes_a_recording_after_the_blink_code(board, tmp_path: Path) -> None:
    out = tmp_path / "run"
    options = [f"--port={board.url}", f"--out={out}", "--duration=1.5", f"--rise={RISE}", f"--fall={FALL}"]
    assert run_cli("board", "record", *options, "--blink", "--bits=12", "--bit-ms=20", "--level=200") == 0
    metadata = json.loads((out / "recording.json").read_text())
    assert metadata["identity"]["name"] == "rig-avr" and metadata["options"]["rise"] == RISE
    assert metadata["events"]["encoder.csv"] == load_table(out, "encoder.csv")["count"].size > 0
    assert metadata["events"]["sync.csv"] >= 2 and metadata["link"]["corrupt"] == 0
    schedule = json.loads((out / "blink.json").read_text())
    led = load_table(out, "led.csv")
    code = BlinkSchedule(schedule["start_board_time"], 0.02, schedule["seed"], 12, 200).code()
    played = led["bit"][np.isfinite(led["bit"])].astype(int)
    assert np.all(code[played] == (led["level"][np.isfinite(led["bit"])] > 0))
    # After the code the LED is left lit, by a command.
    assert np.isnan(led["bit"][-1]) and led["level"][-1] == 200


def test_the_board_records_beside_a_live_session_on_its_clock(board, tmp_path: Path) -> None:
    """The board as one of a session's instruments, as `rig measure --board` runs it: connected with
    the other devices, polled at every refresh, finished at the end, on the session's clock."""
    out = tmp_path
    pendulum = Pendulum(PendulumConfig(), t_end=60.0)
    instrument = BoardInstrument(board.url, out / "board", BoardSettings(rise=RISE, fall=FALL))
    assert isinstance(instrument, Instrument)
    clock = MonotonicClock()
    parts = SessionParts(
        clock, SimTracker(pendulum, TrackerConfig(), 0.0, 60.0, seed=1), predictors.make("hold"), ExternalRenderer(),
        RenderSetup(64, 48, np.eye(4), 0.1), OneImagePerAppFrame(), MeasuredCost(), SimDisplay(DisplayConfig()),
        instruments=[instrument],
    )  # fmt: skip
    with RunRecord(out) as record:
        session = Session(parts, 0.0, 1.5, record, live=True)
        session.run()
    encoder = load_table(out / "board", "encoder.csv")
    assert encoder["count"].size > 0
    # Rig times are the session's clock's, within the run, not the system's monotonic clock.
    assert np.all((encoder["rig_time_s"] > 0.0) & (encoder["rig_time_s"] <= session.t_end + 5.0))
    metadata = json.loads((out / "board" / "recording.json").read_text())
    assert metadata["options"]["rise"] == RISE and metadata["events"]["encoder.csv"] == encoder["count"].size


def test_record_refuses_a_duration_shorter_than_its_blink(tmp_path: Path) -> None:
    with pytest.raises(RigError, match="shorter than the blink"):
        run_cli("board", "record", "--port=loop://", f"--out={tmp_path / 'run'}", "--duration=1", "--blink")
    assert not (tmp_path / "run").exists()


def test_encoder_stream_matches_scripted_pendulum(recording: Path, world) -> None:
    encoder = load_table(recording, "encoder.csv")
    counts_per_swing = 4 * world.amplitude * world.counts_per_rev / (2 * math.pi)
    assert encoder["board_time_s"].size > 0.9 * RECORD_S * counts_per_swing / world.period
    check_edges_follow_script(encoder, world)
    np.testing.assert_array_equal(encoder["edges"], 1)
    # No edge is missing: the script changes count exactly as often between the first and last.
    t = encoder["board_time_s"]
    dense = world.count(np.append(np.arange(t[0] + 1e-6, t[-1], 5e-6), t[-1] + 1e-6))
    assert np.count_nonzero(np.diff(dense)) == t.size - 1
    status = load_table(recording, "status.csv")
    assert np.all(status["quad_invalid"] == 0) and np.all(status["event_overflow"] == 0)


def test_photodiode_crossings_at_scripted_times(recording: Path, world) -> None:
    crossings = load_table(recording, "photodiode.csv")
    t, rising = crossings["board_time_s"], crossings["rising"] > 0.5
    expected, expected_rising = scripted_crossings(world, t[0] - 0.05, t[-1] + 0.05)
    inside = (expected >= t[0] - 1e-3) & (expected <= t[-1] + 1e-3)
    expected, expected_rising = expected[inside], expected_rising[inside]
    assert t.size == expected.size >= 8
    np.testing.assert_array_equal(rising, expected_rising)
    errors = t - expected
    # ADC noise (2 mV), 10-bit steps and 104 us between samples: tens of microseconds.
    assert np.max(np.abs(errors)) < 150e-6
    assert abs(np.mean(errors)) < 30e-6


def test_photodiode_passages_at_the_centroids_of_the_scripted_signal(recording: Path, world) -> None:
    passages = load_table(recording, "passages.csv")
    tick_s = 1 / protocol()["RIG_TICK_HZ"]
    assert passages["board_time_s"].size >= 8
    for start, centroid, end in zip(passages["start_tick"] * tick_s, passages["board_time_s"], passages["end_tick"] * tick_s):
        t = np.arange(start - 2e-3, end + 2e-3, 5e-6)
        excess = np.clip(world.adc_counts(t) - FALL, 0, None)
        assert abs(centroid - np.sum(excess * t) / np.sum(excess)) < 20e-6


def test_board_latency_recovers_scripted_display_delay(recording: Path, world, capsys: pytest.CaptureFixture[str]) -> None:
    assert run_cli("board", "latency", str(recording), "--json") == 0
    latency = json.loads(capsys.readouterr().out)
    assert abs(latency["latency_s"] - world.display_delay) < 0.2e-3
    assert latency["uncertainty_s"] < 0.1e-3
    assert latency["passages_used"] >= 8


def test_blink_code_is_played_on_the_led_pin_and_reported(board) -> None:
    changes: list[LedChange] = []
    arrivals: list[float] = []

    class Collect:
        def on_event(self, event: object) -> None:
            if isinstance(event, LedChange):
                changes.append(event)
                arrivals.append(time.monotonic())

        def on_batch_end(self) -> None:
            pass

    with Microcontroller(board.url) as link:
        link.add_listener(Collect())
        # Another test may have left the LED lit; the blink starts from dark.
        link.set_led(0)
        schedule = link.blink(bits=24, bit_s=0.02, seed=0xACE1, start_in_s=0.1)
        link.wait_for_board_time(schedule.start_board_time + schedule.bits * schedule.bit_s + 0.01, WALL_LIMIT_S)
    start = schedule.start_board_time - 1e-3
    arrivals = [arrival for arrival, change in zip(arrivals, changes) if change.board_time > start]
    changes = [change for change in changes if change.board_time > start]
    code = schedule.code()
    levels = np.where(np.concatenate([code, [False]]), 255, 0)
    flips = [k for k in range(schedule.bits + 1) if levels[k] != (levels[k - 1] if k else 0)]
    assert [change.bit for change in changes] == flips
    assert [change.level for change in changes] == [levels[k] for k in flips]
    planned = schedule.start_board_time + np.array(flips) * schedule.bit_s
    # A change waits at most for the main loop to finish what it is doing (answering the host's
    # status requests, here); the board reports when it really happened.
    late = np.array([change.board_time for change in changes]) - planned
    assert np.all((late >= 0) & (late < 1e-3))
    pin = [line.split(",") for line in board.led_log.read_text().splitlines()[1:]]
    pin_times = np.array([float(t) for t, source, _ in pin if source == "pin" and float(t) > start])
    assert pin_times.size == len(changes)
    # The board dates a change by reading its clock with interrupts held off since the pin changed:
    # a few cycles and the 0.5 us tick. An interrupt in between would add about 10 us.
    assert np.max(np.abs(pin_times - [change.board_time for change in changes])) < 2e-6
    # On the rig clock, each change happened before the host had word of it (give or take the
    # 0.15 ms the emulator may run ahead of the wall clock), and not long before: more than a few
    # milliseconds only if the emulator stood still on a busy machine after the clocks were synced.
    delay = np.array(arrivals) - [change.rig_time for change in changes]
    assert np.all((delay > -0.3e-3) & (delay < 2.0))


def test_recording_survives_line_noise_and_a_dropped_connection(start_board, world, tmp_path: Path) -> None:
    emulated = start_board("--noise-at=2.0", "--noise-at=2.6", "--drop-at=3.5")
    out = tmp_path / "recording"
    recorder = BoardRecorder(out)
    before_drop: list[str] = []
    kinds: list[str] = []

    class SnapshotAtDrop:
        def on_event(self, event: object) -> None:
            if isinstance(event, LinkChange):
                kinds.append(event.kind)
                if event.kind == "lost":
                    recorder.on_batch_end()
                    before_drop.extend((out / "encoder.csv").read_text().splitlines())

        def on_batch_end(self) -> None:
            pass

    try:
        with Microcontroller(emulated.url) as link:
            link.add_listener(recorder)
            link.add_listener(SnapshotAtDrop())
            link.configure_encoder(0)
            link.configure_photodiode(RISE, FALL)
            link.stream(encoder=True, photodiode=True)
            wait_until(lambda: "configured" in kinds, WALL_LIMIT_S, "the board set up again after the drop")
            link.wait_for_board_time(5.5, WALL_LIMIT_S)
            status = link.status()
            counters = link.counters
    finally:
        recorder.close()
    assert counters["corrupt"] + counters["truncated"] + counters["oversize"] + counters["unknown"] >= 1
    assert status.rx_corrupt >= 1
    assert kinds[:2] == ["lost", "restored"] and counters["reconnects"] == 1
    assert [row.split(",")[1] for row in (out / "link.csv").read_text().splitlines()[1:]] == kinds
    lines = (out / "encoder.csv").read_text().splitlines()
    assert len(before_drop) > 100 and lines[: len(before_drop)] == before_drop
    encoder = load_table(out, "encoder.csv")
    assert encoder["board_time_s"].max() > 5.0
    # Every edge received, before and after the noise and the drop, is where the script put it.
    single = encoder["edges"] == 1
    check_edges_follow_script({name: column[single] for name, column in encoder.items()}, world)
