"""The simulated board: its LED blink, its encoder edges against the pendulum, and its recording."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analysis.board.blink_code import lfsr_bits
from analysis.board.recording import load_table
from rig.board.protocol import protocol
from rig.board.recorder import FILES
from rig.clock import VirtualClock
from rig.errors import ConfigError, RigError
from rig.sim.board import SimulatedBoard, SimulatedBoardConfig, encoder_count
from rig.sim.pendulum import Pendulum, PendulumConfig

TICK_HZ = protocol()["RIG_TICK_HZ"]
T_BEGIN, T_END = -0.5, 3.0
RELEASE_S = 0.8


def level_from_changes(changes: list[tuple[float, int, int | None]], t: np.ndarray) -> np.ndarray:
    times = np.array([c[0] for c in changes])
    levels = np.array([c[1] for c in changes])
    index = np.searchsorted(times, t, side="right") - 1
    return np.where(index >= 0, levels[np.maximum(index, 0)], 0)


def test_led_is_on_outside_the_blink_and_follows_the_code_inside() -> None:
    config = SimulatedBoardConfig(blink_start_s=1.0, blink_bits=40, blink_bit_s=0.02, blink_seed=0x1234, blink_level=200)
    centres = 1.0 + (np.arange(40) + 0.5) * 0.02
    np.testing.assert_array_equal(config.led_level(centres), np.where(lfsr_bits(0x1234, 40), 200, 0))
    np.testing.assert_array_equal(config.led_level([-5.0, 0.999, config.blink_end_s, 10.0]), 200)
    # the devices' own reading of the schedule, on the board's clock, agrees inside the blink
    inside = np.linspace(1.0, config.blink_end_s, 997, endpoint=False)
    np.testing.assert_array_equal(config.led_level(inside) > 0, config.schedule().led_on(inside + config.board_offset_s))


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(1, 65535),
    bits=st.integers(1, 80),
    bit_s=st.floats(0.001, 0.2),
    level=st.integers(1, 255),
    samples=st.lists(st.floats(0.0, 1.0), min_size=1, max_size=50),
)
def test_led_changes_rebuild_the_led_level(seed: int, bits: int, bit_s: float, level: int, samples: list[float]) -> None:
    config = SimulatedBoardConfig(blink_start_s=0.5, blink_bits=bits, blink_bit_s=bit_s, blink_seed=seed, blink_level=level)
    changes = config.led_changes(t_on=0.0)
    assert changes[0] == (0.0, level, None)
    levels = [c[1] for c in changes]
    assert all(a != b for a, b in zip(levels, levels[1:])), "consecutive equal levels are not changes"
    assert levels[-1] == level
    for time, _, bit in changes[1:]:
        if bit is None:
            assert time == pytest.approx(config.blink_end_s)
        else:
            assert time == pytest.approx(0.5 + bit * bit_s)
    # sample away from the changes themselves
    t = 0.01 + np.asarray(samples) * (config.blink_end_s + 1.0)
    t = t[np.min(np.abs(t[:, None] - np.array([c[0] for c in changes])[None, :]), axis=1) > 1e-9]
    np.testing.assert_array_equal(level_from_changes(changes, t), config.led_level(t))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(board_offset_s=math.nan), "board.board_offset_s must be a number of seconds from -86400 to 86400, got nan"),
        (dict(blink_start_s=math.inf), "board.blink_start_s must be a number of seconds from 0 to 3600, got inf"),
        (dict(blink_bits=0), "board.blink_bits must be a positive whole number of bits from 1 to 65535, got 0"),
        (dict(blink_bits=65535), "1..65534 bits"),
        (dict(blink_bit_s=0.0005), "at least 1 ms"),
        (dict(blink_seed=0), "board.blink_seed must be a positive whole number from 1 to 65535, got 0"),
        (dict(blink_seed=1 << 16), "board.blink_seed must be a positive whole number from 1 to 65535, got 65536"),
        (dict(blink_level=0), "board.blink_level must be a positive whole number from 1 to 255, got 0"),
        (dict(blink_level=256), "board.blink_level must be a positive whole number from 1 to 255, got 256"),
        (dict(counts_per_rev=3), "board.counts_per_rev must be a positive whole number of counts from 4 to 1e\\+06, got 3"),
    ],
)
def test_bad_board_settings_are_rejected(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        SimulatedBoardConfig(**kwargs)


def test_encoder_count_is_the_emulated_boards_formula() -> None:
    step = 2.0 * np.pi / 2400
    assert encoder_count(0.0, 2400) == 0
    assert encoder_count(0.49 * step, 2400) == 0
    assert encoder_count(0.51 * step, 2400) == 1
    assert encoder_count(-0.51 * step, 2400) == -1
    np.testing.assert_array_equal(encoder_count(np.array([1.5, -2.5]) * step + 1e-12, 2400), [2, -2])


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[Pendulum, SimulatedBoardConfig, Path]:
    """A held, damped pendulum released at RELEASE_S, recorded by a board advanced in uneven steps."""
    pendulum = Pendulum(PendulumConfig(amplitude_deg=25.0, quality=20.0, release_s=RELEASE_S), t_end=T_END + 1.0, t_start=T_BEGIN - 1.0)
    config = SimulatedBoardConfig(board_offset_s=1234.56789, blink_start_s=0.1, blink_bits=16)
    out = tmp_path_factory.mktemp("board")
    board = SimulatedBoard(config, pendulum, T_BEGIN, T_END, out)
    clock = VirtualClock(T_BEGIN)
    board.connect(clock)
    try:
        for t in np.arange(T_BEGIN, T_END, 0.0137):
            clock.wait_until(float(t))
            board.poll()
        clock.wait_until(T_END)
        board.finish()
    finally:
        board.close()
    return pendulum, config, out


def test_encoder_edges_match_the_pendulum_at_their_times(recorded) -> None:
    pendulum, config, out = recorded
    edges = load_table(out, "encoder.csv")
    t, count, step = edges["rig_time_s"], edges["count"], edges["step"]
    assert t.size > 300
    assert np.all(np.diff(t) > 0)
    assert set(np.unique(step)) == {-1.0, 1.0}
    np.testing.assert_array_equal(edges["edges"], 1)
    # each edge steps the count from count - step to count, within a microsecond of its time
    np.testing.assert_array_equal(encoder_count(pendulum.angle(t - 1e-6), 2400), count - step)
    np.testing.assert_array_equal(encoder_count(pendulum.angle(t + 1e-6), 2400), count)
    np.testing.assert_array_equal(count[:-1], count[1:] - step[1:])
    assert count[0] - step[0] == encoder_count(pendulum.angle(T_BEGIN), 2400)


def test_no_encoder_edge_is_missed(recorded) -> None:
    """The count the recording implies equals the pendulum's everywhere on a 20 us grid, so no pair
    of edges at a turning point is lost."""
    pendulum, _, out = recorded
    edges = load_table(out, "encoder.csv")
    grid = np.arange(T_BEGIN, T_END, 20e-6)
    index = np.searchsorted(edges["rig_time_s"], grid, side="right") - 1
    start = edges["count"][0] - edges["step"][0]
    implied = np.where(index >= 0, edges["count"][np.maximum(index, 0)], start)
    np.testing.assert_array_equal(implied, encoder_count(pendulum.angle(grid), 2400))


def test_a_held_pendulum_makes_no_edges_until_its_release(recorded) -> None:
    _, _, out = recorded
    t = load_table(out, "encoder.csv")["rig_time_s"]
    assert t.min() > RELEASE_S
    assert t.min() < RELEASE_S + 0.05
    assert t.max() <= T_END


def test_board_times_are_ticks_of_the_boards_clock(recorded) -> None:
    _, config, out = recorded
    for name in ("encoder.csv", "led.csv"):
        table = load_table(out, name)
        np.testing.assert_array_equal(table["board_time_s"], np.round(table["board_tick"] / TICK_HZ, 9))
        np.testing.assert_allclose(table["board_time_s"] - table["rig_time_s"], config.board_offset_s, rtol=0, atol=0.5 / TICK_HZ + 2e-9)


def test_led_csv_holds_the_switch_on_the_blink_and_the_switch_back(recorded) -> None:
    _, config, out = recorded
    led = load_table(out, "led.csv")
    expected = config.led_changes(T_BEGIN)
    np.testing.assert_allclose(led["rig_time_s"], [c[0] for c in expected], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(led["level"], [c[1] for c in expected])
    np.testing.assert_array_equal(led["bit"], [np.nan if c[2] is None else c[2] for c in expected])
    assert np.isnan(led["bit"][0]) and led["rig_time_s"][0] == pytest.approx(T_BEGIN)


def test_the_recording_has_every_file_of_a_real_one_and_describes_the_board(recorded) -> None:
    _, config, out = recorded
    for name, header in FILES.values():
        assert (out / name).read_text().splitlines()[0] == ",".join(header)
    metadata = json.loads((out / "recording.json").read_text())
    assert metadata["identity"]["tick_hz"] == TICK_HZ
    assert metadata["blink"]["start_board_time"] == pytest.approx(config.blink_start_s + config.board_offset_s)
    assert metadata["release_s"] == RELEASE_S
    assert metadata["events"]["encoder.csv"] == load_table(out, "encoder.csv")["count"].size


def test_events_are_on_disk_as_soon_as_the_clock_passes_them(tmp_path: Path) -> None:
    pendulum = Pendulum(PendulumConfig(), t_end=3.0, t_start=-1.0)
    board = SimulatedBoard(SimulatedBoardConfig(blink_start_s=0.1, blink_bits=8), pendulum, 0.0, 2.0, tmp_path)
    clock = VirtualClock(0.0)
    board.connect(clock)
    try:
        clock.wait_until(0.63)
        board.poll()
        first = load_table(tmp_path, "encoder.csv")["rig_time_s"]
        assert first.size > 100 and first.max() <= 0.63
        clock.wait_until(1.4)
        board.poll()
        second = load_table(tmp_path, "encoder.csv")["rig_time_s"]
        np.testing.assert_array_equal(second[: first.size], first)
        assert 0.63 < second[first.size] and second.max() <= 1.4
        assert load_table(tmp_path, "led.csv")["rig_time_s"].max() <= 0.63 + 8 * 0.05
    finally:
        board.close()


def test_a_folder_holding_a_recording_is_refused(recorded) -> None:
    pendulum, config, out = recorded
    with pytest.raises(RigError, match="already holds a board recording"):
        SimulatedBoard(config, pendulum, T_BEGIN, T_END, out).connect(VirtualClock(T_BEGIN))


def test_an_edge_pair_at_a_turning_point_is_not_lost(tmp_path: Path) -> None:
    """The swing turns 1e-7 rad past a count boundary: the count steps out and back within a
    fraction of a millisecond, between two samples of any coarse grid."""
    k = 100
    amplitude = (k + 0.5) * 2.0 * np.pi / 2400 + 1e-7
    pendulum = Pendulum(PendulumConfig(amplitude_deg=math.degrees(amplitude), quality=math.inf), t_end=2.0)
    board = SimulatedBoard(SimulatedBoardConfig(blink_start_s=0.1, blink_bits=4), pendulum, 0.0, 1.5 * pendulum.period_s, tmp_path)
    board.connect(VirtualClock(1.5 * pendulum.period_s))
    try:
        board.finish()
    finally:
        board.close()
    edges = load_table(tmp_path, "encoder.csv")
    lowest = int(np.argmin(edges["count"]))
    assert edges["count"][lowest] == -(k + 1)
    assert edges["rig_time_s"][lowest] == pytest.approx(pendulum.period_s / 2, abs=1e-3)
    assert edges["count"][lowest + 1] == -k and edges["step"][lowest + 1] == 1
    assert edges["rig_time_s"][lowest + 1] - edges["rig_time_s"][lowest] < 1e-3
