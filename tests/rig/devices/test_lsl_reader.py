"""An LSL inlet pulled by the compiled reader thread (`_readers.LslReader`): every sample an outlet
pushes comes out once, in order, with its LSL stamp and values, stamped on the rig clock between
the readings around its pushing; the reader holds the inlet it pulls until its thread is joined,
and stop() or dropping it ends that thread. An LSL tracker reads through it whatever its clock."""

from __future__ import annotations

import ctypes
import os
import threading
import time
from itertools import count
from typing import Any, Callable

import pytest

from rig.clock import MonotonicClock
from rig.devices.trackers import lsl_tracker as lsl_tracker_module
from rig.devices.trackers import stream as stream_module
from rig.devices.trackers._readers import LslReader
from rig.devices.trackers.lsl_tracker import CHANNELS, OPEN_TIMEOUT_S, RESOLVE_TIMEOUT_S, lsl_tracker, pylsl

pytestmark = pytest.mark.slow

# Long enough never to run out on a loaded machine; a reader that works returns far sooner.
PATIENCE_S = 10.0
_names = count()


@pytest.fixture
def outlet() -> Any:
    """A 7-channel pose outlet with a name of its own."""
    lsl = pylsl()
    name = f"rig-test-reader-{os.getpid()}-{next(_names)}"
    return lsl.StreamOutlet(lsl.StreamInfo(name, "MoCap", len(CHANNELS), 1000.0, lsl.cf_double64, name))


def _inlet(outlet: Any) -> Any:
    lsl = pylsl()
    (info,) = lsl.resolve_byprop("name", outlet.get_info().name(), timeout=RESOLVE_TIMEOUT_S)
    inlet = lsl.StreamInlet(info)
    inlet.open_stream(timeout=OPEN_TIMEOUT_S)
    return inlet


def _reader(inlet: Any, clock: MonotonicClock) -> Any:
    pull = ctypes.cast(pylsl().lib.lib.lsl_pull_sample_d, ctypes.c_void_p).value
    return LslReader(pull, inlet.obj.value, len(CHANNELS), clock.origin_ns, inlet)


def _samples(n: int) -> list[list[float]]:
    return [[0.001 * k, -0.002 * k, 0.5, 1.0, 0.0, 0.0, 0.0] for k in range(n)]


def _take_all(reader: Any, n: int) -> tuple[list, list[float]]:
    chunks: list = []
    arrivals: list[float] = []
    while len(chunks) < n:
        assert reader.wait(PATIENCE_S), "the reader queued nothing"
        taken, times = reader.take()
        chunks += taken
        arrivals += times
    return chunks, arrivals


def test_every_sample_pushed_is_pulled_once_in_order_stamped_on_the_rig_clock(outlet: Any) -> None:
    clock = MonotonicClock()
    inlet = _inlet(outlet)
    reader = _reader(inlet, clock)
    del inlet  # the reader keeps it
    sent = _samples(200)
    before = clock.now()
    stamps = [100.0 + k * 1e-3 for k in range(len(sent))]
    for values, stamp in zip(sent, stamps):
        outlet.push_sample(values, stamp)
    chunks, arrivals = _take_all(reader, len(sent))
    after = clock.now()
    reader.stop()
    assert [list(chunk[1:]) for chunk in chunks] == sent
    assert [chunk[0] for chunk in chunks] == pytest.approx(stamps, abs=1e-9)
    assert before <= arrivals[0] and arrivals[-1] <= after and arrivals == sorted(arrivals)
    assert (reader.outcome, reader.errno) == ("stopped", 0)
    assert reader.cpu_s > 0.0


def test_a_dropped_reader_ends_its_thread(outlet: Any, reader_threads: Callable[[str], set[str]]) -> None:
    inlet = _inlet(outlet)
    before = reader_threads("rig lsl reader")
    reader = _reader(inlet, MonotonicClock())
    (started,) = reader_threads("rig lsl reader") - before
    del reader
    assert started not in reader_threads("rig lsl reader")
    outlet.push_sample(_samples(1)[0], 5.0)
    assert inlet.pull_sample(timeout=PATIENCE_S)[1] == pytest.approx(5.0), "nothing else pulls the inlet any more"


def test_bad_arguments_are_refused() -> None:
    with pytest.raises(ValueError):
        LslReader(0, 1, len(CHANNELS), 0, None)
    with pytest.raises(ValueError):
        LslReader(1, 1, 0, 0, None)


@pytest.mark.parametrize("clock_kind", ["system", "own"])
def test_a_stream_reads_every_sample_through_the_compiled_reader_on_any_clock(
    outlet: Any, clock_kind: str, reader_threads: Callable[[str], set[str]]
) -> None:
    """system: the system's monotonic clock; own: a clock reading the same time through a function
    of the test's, whose origin the stream measures."""
    clock = MonotonicClock() if clock_kind == "system" else MonotonicClock(read_ns=lambda: time.monotonic_ns())
    tracker = lsl_tracker(outlet.get_info().name())
    others = reader_threads("rig lsl reader")
    tracker.connect(clock)
    assert reader_threads("rig lsl reader") - others
    sent = _samples(50)
    for k, values in enumerate(sent):
        outlet.push_sample(values, 200.0 + k * 1e-3)
    records = []
    while len(records) < len(sent):
        records += tracker.wait_records(PATIENCE_S)
    tracker.close()
    assert [list(r.position) for r in records] == [values[:3] for values in sent]
    assert [r.device_time for r in records] == pytest.approx([200.0 + k * 1e-3 for k in range(len(sent))], abs=1e-9)
    assert tracker.report()["counters"]["received"] == len(sent)


def test_clock_corrections_are_measured_on_the_reading_side_never_by_the_consumer(outlet: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """liblsl's time correction can wait on the network: the consumer (a render loop) only hands the
    mapping what the stream's supervising thread measured."""
    monkeypatch.setattr(lsl_tracker_module, "CORRECTION_INTERVAL_S", 0.02)
    monkeypatch.setattr(stream_module, "UPKEEP_INTERVAL_S", 0.01)
    measured_on: list[int] = []
    measure = lsl_tracker_module.time_correction

    def spy(inlet: Any, timeout_s: float) -> tuple[float, float]:
        measured_on.append(threading.get_ident())
        return measure(inlet, timeout_s)

    monkeypatch.setattr(lsl_tracker_module, "time_correction", spy)
    tracker = lsl_tracker(outlet.get_info().name())
    tracker.connect(MonotonicClock())
    measured_on.clear()  # the first is measured by connect(), before any reading
    added = []
    mapping_add = tracker.mapping.add_correction
    monkeypatch.setattr(tracker.mapping, "add_correction", lambda *args, **kwargs: (added.append(args), mapping_add(*args, **kwargs)))
    deadline = time.monotonic() + PATIENCE_S
    k = 0
    while (len(added) < 2 or not measured_on) and time.monotonic() < deadline:
        outlet.push_sample(_samples(1)[0], 300.0 + k * 1e-3)
        k += 1
        tracker.wait_records(0.01)
    tracker.close()
    assert measured_on and threading.get_ident() not in measured_on
    assert len(added) >= 2, "the consumer handed the mapping no fresh correction"
