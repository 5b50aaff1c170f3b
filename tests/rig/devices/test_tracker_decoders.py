"""Decoders resynchronise after damage: every intact record comes out, damage is counted, nothing is
made up; and counters, impossible values and the clock mapping behave as documented."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rig.devices.trackers.clock_mapping import WINDOW_S, CorrectedMapping, OneWayMapping
from rig.devices.trackers.counters import LatencyHistogram, SequenceCheck, TrackerCounters
from rig.devices.trackers.decoders import decoder_for
from rig.devices.trackers.profile import load_profile, parse_profile
from rig.devices.trackers.readings import Readings, keep_possible
from rig.emulate.encode import Emission, RecordEncoder
from rig.sim.fault_plan import parse_faults
from rig.sim.tracker_faults import ByteFaults


def emissions(count: int) -> list[Emission]:
    return [Emission(k, 10.0 + k * 1e-3, (0.001 * k, 0.0, 0.5), (math.cos(0.01 * k), 0.0, 0.0, math.sin(0.01 * k))) for k in range(count)]


@pytest.mark.parametrize("faults", ["corrupt=0.02", "drop=0.02", "garbage=200", "corrupt=0.01,drop=0.01,garbage=100"])
def test_binary_records_survive_damage_without_fabrication(faults: str) -> None:
    profile = load_profile("binary-pose")
    encoder, damage = RecordEncoder(profile), ByteFaults(parse_faults(faults), seed=1)
    stream, intact, damaged = b"", [], 0
    for emission in emissions(2000):
        data, hurt = damage.apply(encoder.encode(emission), 1000.0)
        stream += data
        if hurt:
            damaged += 1
        else:
            intact.append(emission.seq)
    decoder = decoder_for(profile)
    pieces = np.random.default_rng(2).integers(1, 97, 4000)
    seqs, at = [], 0
    for size in pieces:
        seqs += decoder.feed(stream[at : at + size], 0.0).seqs
        at += size
    seqs += decoder.feed(stream[at:], 0.0).seqs
    decoder.reset()
    assert seqs == intact
    assert decoder.corrupt >= damaged
    if "garbage" not in faults:
        assert decoder.corrupt == damaged, "a damaged stretch counts as the records it held"


def test_text_lines_skip_their_header_and_count_bad_lines() -> None:
    decoder = decoder_for(load_profile("csv"))
    text = b"t,px,py,pz,qw,qx,qy,qz\n1.0,0,0,0,1,0,0,0\n1.001,0,0,x,1,0,0,0\n1.002,0,0\n1.00"
    first, second = decoder.feed(text, 5.0), decoder.feed(b"3,0,0,0,1,0,0,0\n", 6.0)
    assert list(zip(first.device_times + second.device_times, first.arrivals + second.arrivals)) == [(1.0, 5.0), (1.003, 6.0)]
    assert decoder.corrupt == 2


@pytest.mark.parametrize("profile_name", ["binary-pose", "csv"])
def test_chunks_fed_together_stamp_each_record_with_the_chunk_that_completed_it(profile_name: str) -> None:
    """A reader's queued chunks decoded in one feed: the same records, in order, as fed one by one,
    each with the arrival of the chunk holding its last byte, even where that chunk holds nothing
    else of it (a record cut just before its last byte)."""
    encoder = RecordEncoder(load_profile(profile_name))
    records = [encoder.encode(e) for e in emissions(40)]
    wire = b"".join(records)
    record_ends = np.cumsum([len(r) for r in records])
    cuts = sorted({*np.random.default_rng(4).integers(1, len(wire), 30).tolist(), *(record_ends[:5] - 1).tolist()})
    chunks = [wire[a:b] for a, b in zip([0, *cuts], [*cuts, len(wire)])]
    arrivals = [100.0 + k for k in range(len(chunks))]
    chunk_ends = np.cumsum([len(c) for c in chunks])
    together, apart = decoder_for(load_profile(profile_name)), decoder_for(load_profile(profile_name))
    readings = [together.feed_chunks(chunks[:17], arrivals[:17]), together.feed_chunks(chunks[17:], arrivals[17:])]
    one_by_one = [apart.feed(chunk, t) for chunk, t in zip(chunks, arrivals)]
    completed_by = [arrivals[int(np.searchsorted(chunk_ends, end))] for end in record_ends]
    assert [t for r in readings for t in r.arrivals] == [t for r in one_by_one for t in r.arrivals] == completed_by
    device_times = [t for r in readings for t in r.device_times]
    assert device_times == pytest.approx([e.device_time for e in emissions(40)], abs=1e-6)
    assert together.corrupt == apart.corrupt == 0


def _readings(orientations: list[tuple], positions: list[tuple] | None = None, discarded: dict[int, int] | None = None) -> Readings:
    count = len(orientations)
    positions = positions or [(0.0, 0.0, 0.0)] * count
    return Readings([float(k) for k in range(count)], None, list(range(count)), positions, orientations, None, discarded or {})


def test_impossible_values_are_refused_and_possible_ones_normalised() -> None:
    readings = _readings(
        [(1.0, 0.1, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), (math.inf, 0.0, 0.0, 0.0), (1.0002, 0.0, 0.0, 0.0)],
        [(0.0, 0.0, 0.0), (math.nan, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)],
    )
    problems = keep_possible(readings, 1e-3)
    assert ["norm" in problems[0], "finite" in problems[1], "finite" in problems[2]] == [True] * 3
    assert readings.orientations == [(1.0, 0.0, 0.0, 0.0)] and readings.seqs == [3]


def test_impossible_readings_count_as_discarded_before_the_next_possible_one() -> None:
    """Among possible ones in a batch: an impossible reading, and the damage before it, are told to
    the next possible reading, or to the batch's end where none follows."""
    bad, good = (2.0, 0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)
    readings = _readings([good, bad, good, bad, bad], discarded={1: 2, 3: 1})
    keep_possible(readings, 1e-3)
    assert readings.seqs == [0, 2]
    assert readings.discarded == {1: 3, 2: 3}


def test_a_batch_whose_sums_overflow_is_checked_reading_by_reading() -> None:
    """Positions near the largest float: each reading's own sum is finite, the batch's is not."""
    huge = 1e308
    readings = _readings([(1.0, 0.0, 0.0, 0.0)] * 3, [(huge, 0.0, 0.0), (huge, 0.0, 0.0), (huge, huge, 0.0)])
    problems = keep_possible(readings, 1e-3)
    assert len(problems) == 1 and "finite" in problems[0] and readings.seqs == [0, 1]


def test_a_16_bit_counter_wraps_and_gaps_count_as_dropped_less_the_damaged() -> None:
    counters = TrackerCounters()
    check = SequenceCheck(counters, 16)
    check.accept(Readings([0.0] * 4, None, [65534, 65535, 0, 3], [], []))
    check.accept(Readings([], None, [], [], [], None, {0: 2}))
    check.accept(Readings([0.0] * 2, None, [7, 6], [], []))
    assert (counters.dropped, counters.out_of_order) == (2 + 1, 1)


def test_one_way_mapping_removes_jitter_and_finds_drift() -> None:
    rng = np.random.default_rng(4)
    rate, drift, floor = 500.0, 80e-6, 0.004
    sensed = np.arange(int(6.0 * rate)) / rate
    device = 1000.0 + sensed * (1.0 + drift)
    arrival = sensed + floor + rng.exponential(0.0005, sensed.size)
    mapping = OneWayMapping(1e-6)
    mapped = []
    for d, a in zip(device, arrival):
        mapping.observe_many([d], [a])
        mapped.extend(mapping.sensor_times([d], [a]))
    settled = arrival > 2 * WINDOW_S
    error = np.array(mapped)[settled] - (sensed[settled] + floor)
    assert np.all(np.array(mapped) <= arrival)
    assert np.abs(error).max() < 2e-4, "the fastest transfer's floor, without the jitter (mean 0.5 ms)"
    described = mapping.describe()
    assert described["drift_ppm"] == pytest.approx(drift * 1e6, abs=max(5.0, 3 * described["drift_uncertainty_ppm"]))


def test_records_mapped_together_get_the_times_each_would_get_alone() -> None:
    rng = np.random.default_rng(5)
    sensed = np.arange(2000) / 500.0
    device = 1000.0 + sensed * (1.0 + 80e-6)
    arrival = sensed + 0.004 + rng.exponential(0.0005, sensed.size)
    mapping = OneWayMapping(1e-6)
    for d, a in zip(device, arrival):
        mapping.observe_many([d], [a])
    together = mapping.sensor_times(device.tolist(), arrival.tolist())
    assert together == [mapping.sensor_times([d], [a])[0] for d, a in zip(device, arrival)]
    assert np.all(np.diff(together) > 0), "records taken together keep their order in sensor time"


def test_one_way_mapping_follows_a_device_clock_that_restarts() -> None:
    mapping = OneWayMapping(1e-6)
    for k in range(1000):
        mapping.observe_many([500.0 + k * 1e-3], [k * 1e-3 + 0.002])
    mapping.restart()
    t = 1.5
    mapping.observe_many([0.0], [t])
    assert mapping.sensor_times([0.0], [t]) == pytest.approx([t])


def test_corrected_mapping_applies_the_round_trip_offset() -> None:
    mapping = CorrectedMapping()
    mapping.origin_s = 100.0
    mapping.add_correction(0.25, 1e-4, at=1.0)
    # The sender's time 50.75 is local time 51.0, which is rig time 51.0 - 100.0.
    assert mapping.sensor_times([50.75], [0.0]) == pytest.approx([-49.0])
    assert mapping.describe()["offset_interval_s"] == pytest.approx([100.0 - 0.25 - 1e-4, 100.0 - 0.25 + 1e-4])


def test_the_latency_histogram_keeps_impossible_latencies_in_its_end_bins() -> None:
    histogram = LatencyHistogram()
    histogram.add_many([-0.5, 1e12, 0.001055])
    assert histogram.count == 3
    assert histogram.quantile_ms(0.0) == pytest.approx(0.005), "a negative latency counts in the first bin"
    assert histogram.quantile_ms(0.5) == pytest.approx(1.055), "1.055 ms falls in the bin from 1.05 to 1.06 ms"
    assert histogram.quantile_ms(1.0) == pytest.approx(2000.0 - 0.005), "beyond 2 s counts in the last bin"


def test_integer_fields_with_unit_scale_decode_to_floats() -> None:
    profile = parse_profile(
        'format = "binary"\nsync = "a5"\nfields = ["px:i16", "py:i16", "pz:i16", "qw:f32", "qx:f32", "qy:f32", "qz:f32"]\n',
        "test", "integer-position",
    )
    sent = Emission(0, 0.0, (3.0, -2.0, 1.0), (1.0, 0.0, 0.0, 0.0))
    readings = decoder_for(profile).feed(RecordEncoder(profile).encode(sent), 1.0)
    assert readings.positions == [(3.0, -2.0, 1.0)] and all(type(v) is float for v in readings.positions[0])
    assert readings.orientations == [(1.0, 0.0, 0.0, 0.0)] and readings.device_times is None


@pytest.mark.parametrize("checksum", ["none", "crc32"])
def test_padding_before_the_fields_takes_no_value(checksum: str) -> None:
    profile = parse_profile(
        f'format = "binary"\nsync = "a5"\nchecksum = "{checksum}"\n'
        'fields = ["_:pad2", "t:u32", "x:pad1", "qw:f32", "qx:f32", "qy:f32", "qz:f32"]\n',
        "test", "padded",
    )
    sent = Emission(0, 12.0, (0.0, 0.0, 0.0), (0.6, 0.8, 0.0, 0.0))
    readings = decoder_for(profile).feed(RecordEncoder(profile).encode(sent), 1.0)
    assert readings.device_times == [12.0]
    assert readings.orientations == [pytest.approx((0.6, 0.8, 0.0, 0.0), abs=1e-7)]


def test_the_latency_histogram_gives_median_and_95th_percentile() -> None:
    histogram = LatencyHistogram()
    histogram.add_many(np.linspace(0.0, 0.01, 1001).tolist())
    assert histogram.quantile_ms(0.5) == pytest.approx(5.0, abs=0.02)
    assert histogram.quantile_ms(0.95) == pytest.approx(9.5, abs=0.02)


def test_a_partial_line_left_at_a_reset_is_one_corrupt_record() -> None:
    decoder = decoder_for(load_profile("csv"))
    decoder.feed(b"1.0,0,0,0,1,0,0,0\n1.001,0,0,", 5.0)
    decoder.reset()
    decoder.reset()
    assert decoder.corrupt == 1


class _OneReadPort:
    """A port without a file descriptor that gives `data` at its first read and nothing after."""

    def __init__(self, data: bytes) -> None:
        self._data = data

    @property
    def in_waiting(self) -> int:
        return len(self._data)

    def read(self, size: int = 1) -> bytes:
        data, self._data = self._data[:size], self._data[size:]
        return data

    def close(self) -> None:
        pass


def test_a_damaged_last_record_is_counted_once_the_stream_is_closed() -> None:
    from rig.clock import MonotonicClock
    from rig.devices.trackers.serial_tracker import serial_tracker

    encoder = RecordEncoder(load_profile("binary-pose"))
    records = [encoder.encode(e) for e in emissions(3)]
    damaged = records[2][:-1] + bytes([records[2][-1] ^ 0xFF])
    tracker = serial_tracker("fake?profile=binary-pose", open_port=lambda url, baud: _OneReadPort(b"".join(records[:2]) + damaged))
    tracker.connect(MonotonicClock())
    received = []
    while len(received) < 2:
        received += tracker.wait_records(0.05)
    tracker.close()
    assert tracker.take_queued() == []
    assert (tracker.counters.received, tracker.report()["counters"]["corrupt"]) == (2, 1)


def test_a_damaged_record_between_intact_ones_of_one_chunk_is_not_counted_dropped() -> None:
    from rig.clock import MonotonicClock
    from rig.devices.trackers.serial_tracker import serial_tracker

    encoder = RecordEncoder(load_profile("binary-pose"))
    records = [encoder.encode(e) for e in emissions(4)]
    records[2] = records[2][:-1] + bytes([records[2][-1] ^ 0xFF])
    tracker = serial_tracker("fake?profile=binary-pose", open_port=lambda url, baud: _OneReadPort(b"".join(records)))
    tracker.connect(MonotonicClock())
    received = []
    while len(received) < 3:
        received += tracker.wait_records(0.05)
    tracker.close()
    assert [r.seq for r in received] == [0, 1, 3]
    counters = tracker.report()["counters"]
    assert (counters["corrupt"], counters["dropped"]) == (1, 0), "record 2 arrived damaged: counted corrupt, not dropped"


@pytest.mark.parametrize("profile_name", ["binary-pose", "csv", "polhemus-ascii"])
def test_a_record_cut_at_every_byte_offset_decodes_once_stamped_by_its_last_byte(profile_name: str) -> None:
    """Three records in two feeds, cut at every byte (in a sync, a check, a two-byte terminator)."""
    profile = load_profile(profile_name)
    encoder = RecordEncoder(profile)
    records = [encoder.encode(e) for e in emissions(3)]
    wire, ends = b"".join(records), np.cumsum([len(r) for r in records]).tolist()
    whole = decoder_for(profile).feed(wire, 1.0)
    assert len(whole) == 3
    for cut in range(1, len(wire)):
        decoder = decoder_for(profile)
        first, second = decoder.feed(wire[:cut], 1.0), decoder.feed(wire[cut:], 2.0)
        assert first.positions + second.positions == whole.positions, f"cut at byte {cut}"
        assert first.orientations + second.orientations == whole.orientations
        assert first.arrivals + second.arrivals == [1.0 if end <= cut else 2.0 for end in ends]
        assert decoder.corrupt == 0


def test_garbage_and_a_damaged_record_inside_one_feed_are_told_to_the_next_intact_record() -> None:
    """Garbage holding a false sync after record 0, and record 2 with a bad check: one feed gives
    records 0, 1 and 3, each damaged stretch counted once, before the record that follows it."""
    profile = load_profile("binary-pose")
    encoder = RecordEncoder(profile)
    records = [encoder.encode(e) for e in emissions(4)]
    size = len(records[0])
    garbage = b"\x01\x02" + profile.sync + b"\x03" * 5
    damaged = records[2][:-1] + bytes([records[2][-1] ^ 0xFF])
    decoder = decoder_for(profile)
    readings = decoder.feed(records[0] + garbage + records[1] + damaged + records[3], 1.0)
    assert readings.seqs == [0, 1, 3]
    assert readings.discarded == {1: math.ceil(len(garbage) / size), 2: 1}
    assert decoder.corrupt == math.ceil(len(garbage) / size) + 1


def test_a_bad_line_among_good_ones_of_one_feed_is_told_to_the_next_good_line() -> None:
    decoder = decoder_for(load_profile("csv"))
    readings = decoder.feed(b"1.0,0,0,0,1,0,0,0\n1.001,0,x\n1.002,0,0,0,1,0,0,0\n1.003,0,0,0,1,0,0,0\n", 5.0)
    assert readings.device_times == [1.0, 1.002, 1.003] and readings.arrivals == [5.0] * 3
    assert readings.discarded == {1: 1} and decoder.corrupt == 1


def _split(items: list, cuts: list[int]) -> list[list]:
    bounds = [0, *sorted(set(cuts)), len(items)]
    return [items[a:b] for a, b in zip(bounds, bounds[1:])]


def test_counters_are_the_same_whichever_batches_the_readings_come_in() -> None:
    """A 16-bit counter with drops, repeats, late records, discards, wraps and a reconnection after
    which it goes on, then one after which it starts again: counted in batches of any size as one
    record at a time."""
    rng = np.random.default_rng(7)
    seqs = [int(s) % 65536 for s in np.cumsum(rng.choice([1, 1, 1, 1, 2, 5, 0, -3], 3000)) + 65000]
    discarded = {k: int(rng.integers(1, 3)) for k in rng.choice(len(seqs), 60, replace=False).tolist()}
    restores = [1000, 2000]
    seqs[2000:] = [(s - 40000) % 65536 for s in seqs[2000:]]

    def counted(cuts: list[int]) -> TrackerCounters:
        counters = TrackerCounters()
        check = SequenceCheck(counters, 16)
        for batch in _split(list(range(len(seqs))), [*cuts, *restores]):
            if batch and batch[0] in restores:
                check.link_restored()
            told = {k - batch[0]: discarded[k] for k in batch if k in discarded}
            check.accept(Readings([0.0] * len(batch), None, [seqs[k] for k in batch], [], [], None, told))
        return counters

    one_by_one = counted(list(range(len(seqs))))
    assert one_by_one.dropped > 0 and one_by_one.out_of_order > 0
    for seed in range(3):
        cuts = np.random.default_rng(seed).integers(0, len(seqs), 150).tolist()
        assert counted(cuts) == one_by_one


def test_the_one_way_mapping_learns_the_same_from_batches_as_from_single_records() -> None:
    rng = np.random.default_rng(8)
    sensed = np.arange(3000) / 1000.0
    device = (1000.0 + sensed * (1.0 + 50e-6)).tolist()
    arrival = (sensed + 0.004 + rng.exponential(0.0005, sensed.size)).tolist()
    apart, together = OneWayMapping(1e-6), OneWayMapping(1e-6)
    for d, a in zip(device, arrival):
        apart.observe_many([d], [a])
    for indices in _split(list(range(len(device))), rng.integers(0, len(device), 200).tolist()):
        together.observe_many([device[k] for k in indices], [arrival[k] for k in indices])
    assert together.model.intervals == apart.model.intervals
    assert together.sensor_times(device[-50:], arrival[-50:]) == apart.sensor_times(device[-50:], arrival[-50:])
