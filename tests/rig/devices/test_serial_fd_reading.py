"""A serial port with a file descriptor is waited on and read in one call: the compiled
`_fd_wait.wait_read` and its pure-Python fallback (a poll object) give the same bytes, None when
nothing came, b"" at the end, OSError on a closed descriptor; a serial tracker reads the same
records through either."""

from __future__ import annotations

import os
from typing import Iterator

import pytest

from rig.clock import MonotonicClock
from rig.devices.trackers import serial_tracker as serial_module
from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.serial_tracker import serial_tracker, waiting_reader
from rig.emulate.encode import Emission, RecordEncoder

@pytest.fixture(params=["compiled", "python"])
def implementation(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    if request.param == "compiled":
        assert serial_module.wait_read is not None, "rig.devices.trackers._fd_wait is built by pip install -e ."
    else:
        monkeypatch.setattr(serial_module, "wait_read", None)
    return request.param


class Pipe:
    """Both ends of an os.pipe; each closed once, by the test or afterwards."""

    def __init__(self) -> None:
        self.read_end, self.write_end = os.pipe()
        self._open = {self.read_end, self.write_end}

    def close(self, fd: int) -> None:
        if fd in self._open:
            self._open.remove(fd)
            os.close(fd)


@pytest.fixture
def pipe() -> Iterator[Pipe]:
    made = Pipe()
    yield made
    made.close(made.read_end)
    made.close(made.write_end)


def test_what_a_descriptor_holds_is_read_whole_and_nothing_more(implementation: str, pipe: Pipe) -> None:
    read = waiting_reader(pipe.read_end)
    data = bytes(range(256)) * 3
    os.write(pipe.write_end, data)
    assert read(0, 100) == data[:100]
    assert read(0, 65536) == data[100:]
    assert read(0, 65536) is None, "nothing waiting: None once the (zero) timeout has passed"
    pipe.close(pipe.write_end)
    assert read(0, 65536) == b"", "the other end went away"


def test_a_closed_descriptor_raises_os_error(implementation: str, pipe: Pipe) -> None:
    read = waiting_reader(pipe.read_end)
    os.write(pipe.write_end, b"x")
    pipe.close(pipe.read_end)
    with pytest.raises(OSError):
        read(0, 16)


def test_the_compiled_reader_refuses_a_negative_size() -> None:
    if serial_module.wait_read is None:
        pytest.fail("rig.devices.trackers._fd_wait is built by pip install -e .")
    with pytest.raises(ValueError):
        serial_module.wait_read(0, 0, -1)


class _PipePort:
    """A port with a file descriptor, as pyserial's for a device, a pty or a socket."""

    def __init__(self, fd: int) -> None:
        self._fd = fd

    def fileno(self) -> int:
        return self._fd

    @property
    def in_waiting(self) -> int:
        raise AssertionError("a port with a descriptor is read straight from it")

    def read(self, size: int = 1) -> bytes:
        raise AssertionError("a port with a descriptor is read straight from it")

    def close(self) -> None:
        pass


def test_a_serial_tracker_reads_the_same_records_either_way(implementation: str, pipe: Pipe) -> None:
    encoder = RecordEncoder(load_profile("binary-pose"))
    sent = [Emission(k, 1.0 + k * 1e-3, (0.01 * k, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0)) for k in range(50)]
    os.write(pipe.write_end, b"".join(encoder.encode(e) for e in sent))
    tracker = serial_tracker("pipe?profile=binary-pose", open_port=lambda url, baud: _PipePort(pipe.read_end))
    tracker.connect(MonotonicClock())
    records = []
    while len(records) < len(sent):
        records += tracker.wait_records(1.0)
    tracker.close()
    assert [r.seq for r in records] == [e.seq for e in sent]
    assert [r.device_time for r in records] == pytest.approx([e.device_time for e in sent], abs=1e-6)
    assert tracker.report()["counters"]["corrupt"] == 0
