"""Clock offsets as intervals: bounds from round trips, narrowing, drift, tick unwrapping."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.board.intervals import consistent_intersection
from rig.board.clock_sync import CLOCK_RESTART_S, ClockModel, OffsetInterval, RoundTrip, TickUnwrapper, narrow

BYTE_TIME = 10 / 500_000
REQUEST_BYTES = 6


def round_trip(offset: float, sent: float, to_board: float, processing: float, back: float) -> RoundTrip:
    """A round trip with the given true offset and delays: to_board is the request's time on the
    line beyond its own length, back the answer's delay after its last byte went out."""
    board_rx = sent + REQUEST_BYTES * BYTE_TIME + to_board + offset
    board_tx = board_rx + processing
    return RoundTrip(sent=sent, received=board_tx - offset + back, board_rx=board_rx, board_tx=board_tx)


positive = st.floats(0, 0.01)


@given(st.floats(-1e4, 1e4), st.floats(0, 1e4), positive, positive, positive)
def test_bounds_always_hold_the_true_offset(offset: float, sent: float, to_board: float, processing: float, back: float) -> None:
    interval = round_trip(offset, sent, to_board, processing, back).bounds(REQUEST_BYTES, BYTE_TIME)
    assert interval.low <= offset + 1e-9 and offset - 1e-9 <= interval.high
    assert interval.width == pytest.approx(to_board + back, abs=1e-9)


def test_many_round_trips_narrow_the_interval_around_the_offset() -> None:
    rng = np.random.default_rng(3)
    offset = 123.456789
    trips = [
        round_trip(offset, 10 + 0.002 * k, *rng.exponential(300e-6, size=3)).bounds(REQUEST_BYTES, BYTE_TIME)
        for k in range(100)
    ]
    interval, left_out = narrow(trips)
    assert left_out == 0 and interval.round_trips == 100
    assert interval.low <= offset <= interval.high
    assert interval.width < 30e-6 < np.median([trip.width for trip in trips]) / 10


def test_a_round_trip_that_disagrees_is_left_out() -> None:
    trips = [OffsetInterval(1.0, 1.1, 0.0), OffsetInterval(1.05, 1.2, 1.0), OffsetInterval(2.0, 2.1, 2.0), OffsetInterval(1.02, 1.07, 3.0)]
    interval, left_out = narrow(trips)
    assert (interval.low, interval.high, interval.round_trips, left_out) == (1.05, 1.07, 3, 1)
    assert interval.at == pytest.approx(4.0 / 3)
    low, high, members = consistent_intersection([0.0, 5.0], [1.0, 6.0])
    assert len(members) == 1 and high - low == 1.0
    with pytest.raises(ValueError):
        narrow([])


def test_drift_is_measured_from_intervals_far_enough_apart() -> None:
    model = ClockModel()
    rate = 40e-6
    for at in (0.0, 0.5):
        model.add(OffsetInterval(5.0 + rate * at - 20e-6, 5.0 + rate * at + 20e-6, at))
    assert model.drift() is None
    model.add(OffsetInterval(5.0 + rate * 20 - 20e-6, 5.0 + rate * 20 + 20e-6, 20.0))
    drift = model.drift()
    assert drift.rate == pytest.approx(rate, abs=drift.uncertainty)
    assert drift.uncertainty == pytest.approx(40e-6 / 20)
    # Extrapolation after the latest interval follows the drift; interpolation between them is linear.
    assert model.offset_at(30.0) == pytest.approx(5.0 + rate * 30, abs=1e-9)
    assert model.offset_at(10.25) == pytest.approx(5.0 + rate * 0.5 + rate * 19.5 * 0.5, abs=1e-9)


@given(st.floats(-1e3, 1e3), st.floats(0, 1e4))
def test_board_to_rig_time_inverts_the_offset(offset: float, rig_time: float) -> None:
    model = ClockModel()
    model.add(OffsetInterval(offset - 1e-5, offset + 1e-5, 0.0))
    model.add(OffsetInterval(offset + 2e-4 - 1e-5, offset + 2e-4 + 1e-5, 100.0))
    board_time = rig_time + model.offset_at(rig_time)
    assert model.to_rig_time(board_time) == pytest.approx(rig_time, abs=1e-9)


@given(st.lists(st.floats(-10.0, 40.0), max_size=30), st.integers(1, 4))
def test_offsets_of_many_times_are_the_offsets_of_each(times: list[float], measurements: int) -> None:
    model = ClockModel()
    for k in range(measurements):
        offset = 5.0 + 40e-6 * 10.0 * k
        model.add(OffsetInterval(offset - 20e-6, offset + 20e-6, 10.0 * k))
    assert model.offsets_at(times) == [model.offset_at(t) for t in times]
    assert model.to_rig_times(times) == [model.to_rig_time(t) for t in times]


def test_a_board_clock_restart_starts_a_new_run() -> None:
    model = ClockModel()
    model.add(OffsetInterval(100.0, 100.0001, 0.0))
    model.add(OffsetInterval(100.0, 100.0001, 5.0))
    model.add(OffsetInterval(-50.0, -49.9999, 6.0))
    assert len(model.intervals) == 3
    assert model.offset_at(7.0) == pytest.approx(-49.99995)
    assert model.drift() is None
    model.add(OffsetInterval(-50.0 + CLOCK_RESTART_S / 2, -49.9999 + CLOCK_RESTART_S / 2, 7.0))
    assert model.latest.at == 7.0 and len(model.intervals) == 4


def test_an_unsynchronised_model_refuses_to_convert() -> None:
    with pytest.raises(ValueError, match="not been synchronised"):
        ClockModel().to_rig_time(1.0)


def test_ticks_unwrap_across_the_32_bit_wrap() -> None:
    unwrap = TickUnwrapper()
    assert unwrap.anchor(epoch=2, tick=0xFFFF_FF00) == (2 << 32) + 0xFFFF_FF00
    assert unwrap.unwrap(0xFFFF_FFF0) == (2 << 32) + 0xFFFF_FFF0
    assert unwrap.unwrap(0x10) == (3 << 32) + 0x10
    assert unwrap.unwrap(0xFFFF_FFFF) == (2 << 32) + 0xFFFF_FFFF  # slightly older: back across the wrap
    unwrap.reset()
    assert unwrap.unwrap(5) == 5


@pytest.mark.parametrize("bits", [16, 32])
def test_ticks_unwrapped_together_are_those_unwrapped_one_by_one(bits: int) -> None:
    """Batches that wrap, go back a little, or jump, among many that do not."""
    wrap = 1 << bits
    rng = np.random.default_rng(bits)
    steps = rng.choice([1, 1, 1, 7, -2, wrap // 2 - 1, wrap // 3], 4000)
    ticks = [int(t) % wrap for t in np.cumsum(steps) + wrap - 50]
    apart, together = TickUnwrapper(bits), TickUnwrapper(bits)
    one_by_one = [apart.unwrap(tick) for tick in ticks]
    bounds = [0, *sorted(set(rng.integers(0, len(ticks), 300).tolist())), len(ticks)]
    batched = [full for a, b in zip(bounds, bounds[1:]) for full in together.unwrap_many(ticks[a:b])]
    assert batched == one_by_one
