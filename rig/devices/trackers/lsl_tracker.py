"""`lsl:NAME`: a pose stream on Lab Streaming Layer, as motion capture systems and game engines
publish them: 7 channels, position in metres (px, py, pz) then a unit quaternion w first (qw, qx,
qy, qz), each sample stamped on the sender's LSL clock.

The inlet is pulled by a compiled thread (`_readers.LslReader`, calling liblsl's
`lsl_pull_sample_d` as pylsl loaded it), one sample a chunk; `LslSampleDecoder` reads the chunks.
The sender's stamps are mapped onto the rig clock with liblsl's own clock offset, measured by round
trips (`lsl_time_correction_ex`, which gives the offset's uncertainty beside it; pylsl exposes only
the offset) and refreshed every CORRECTION_INTERVAL_S by the transport's upkeep (the stream's
supervising thread, never the consumer's: liblsl's answer can wait on the network, and the
consumer may be a render loop), so the tracker's latency to the host is known. The inlet recovers a
sender that restarts (same source id) by itself. pylsl is imported only when an LSL stream is used
or listed, and liblsl's own console log is kept to fatal errors: the rig logs what happens to the
link itself.
"""

from __future__ import annotations

import ctypes
import time
from operator import itemgetter
from types import ModuleType
from typing import Any, Callable, Sequence, TypeVar

from rig import interrupts
from rig.clock import Clock
from rig.devices.trackers.clock_mapping import CorrectedMapping
from rig.devices.trackers.profile import DEFAULT_UNIT_TOLERANCE
from rig.devices.trackers.readings import Readings
from rig.devices.trackers.stream import TrackerStream
from rig.devices.trackers.transport import NS_PER_S, Reader, monotonic_origin_ns
from rig.errors import ConfigError, RigError

try:
    from rig.devices.trackers._readers import LslReader
except ImportError:
    LslReader = None

CHANNELS = ("px", "py", "pz", "qw", "qx", "qy", "qz")
CHANNEL_UNITS = ("metres",) * 3 + ("normalised",) * 4
_STAMP, _POSITION, _ORIENTATION = itemgetter(0), itemgetter(1, 2, 3), itemgetter(4, 5, 6, 7)
RESOLVE_TIMEOUT_S = 2.0
RESOLVE_POLL_S = 0.1
OPEN_TIMEOUT_S = 2.0
CORRECTION_INTERVAL_S = 1.0
CORRECTION_TIMEOUT_S = 2.0
WAIT_SLICE_S = 0.2
"""The longest liblsl is left waiting in C at once, deaf to signals: a Ctrl-C or SIGTERM that came
meanwhile is raised between slices (`in_slices`)."""
# Seconds of samples the inlet buffers while the reader is busy: far more than it ever is.
BUFFER_S = 30
_LIBLSL_CONFIG = "[log]\nlevel = -3\n"
_pylsl: ModuleType | None = None
READER_MISSING = "rig.devices.trackers._readers is not built, and an LSL inlet is read by it: reinstall the package (pip install -e .)"


def pylsl() -> ModuleType:
    """pylsl, imported on first use with liblsl's console log kept to fatal errors."""
    global _pylsl
    if _pylsl is None:
        import pylsl as module

        module.set_config_content(_LIBLSL_CONFIG)
        _pylsl = module
    return _pylsl


def resolve_streams(wait_s: float, name: str | None = None) -> list[Any]:
    """The LSL streams (pylsl StreamInfo) seen within `wait_s` seconds; with `name`, those of that
    name, returned as soon as one answers. pylsl's own resolve waits inside liblsl, deaf to Ctrl-C
    and SIGTERM for the whole wait; this one listens in steps of RESOLVE_POLL_S, so a signal stops
    it at once."""
    lsl = pylsl()
    resolver = lsl.ContinuousResolver() if name is None else lsl.ContinuousResolver(prop="name", value=name)
    deadline = time.monotonic() + wait_s
    while True:
        found = resolver.results()
        left = deadline - time.monotonic()
        if left <= 0 or (found and name is not None):
            return found
        time.sleep(min(RESOLVE_POLL_S, left))


Answer = TypeVar("Answer")


def in_slices(call: Callable[[float], Answer], timeout_s: float) -> Answer:
    """`call(slice_s)`, a liblsl wait of at most `slice_s` seconds, made again until it answers or
    `timeout_s` has passed (liblsl's TimeoutError then): liblsl goes on with what it started between
    calls (a connection, a clock measurement), and a pending interrupt is raised between them, on
    any thread (`rig.interrupts`), so a signal stops the wait within WAIT_SLICE_S."""
    timeout_error = pylsl().util.TimeoutError
    deadline = time.monotonic() + timeout_s
    while True:
        interrupts.raise_pending()
        left = deadline - time.monotonic()
        try:
            return call(max(min(WAIT_SLICE_S, left), 0.0))
        except timeout_error:
            if left <= WAIT_SLICE_S:
                raise
            interrupts.raise_pending()


def open_inlet(inlet: Any, timeout_s: float) -> None:
    """Subscribe `inlet` to its stream's samples, waiting at most `timeout_s` (`in_slices`)."""
    in_slices(lambda slice_s: inlet.open_stream(timeout=slice_s), timeout_s)


def time_correction(inlet: Any, timeout_s: float) -> tuple[float, float]:
    """(offset, uncertainty) in seconds: local time = the sender's time + offset, within +-uncertainty;
    waiting at most `timeout_s` for liblsl's measurement (`in_slices`)."""
    return in_slices(lambda slice_s: _time_correction(inlet, slice_s), timeout_s)


def _time_correction(inlet: Any, timeout_s: float) -> tuple[float, float]:
    lsl = pylsl()
    function = lsl.lib.lib.lsl_time_correction_ex
    function.restype = ctypes.c_double
    function.argtypes = [
        ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double), ctypes.c_double,
        ctypes.POINTER(ctypes.c_int32),
    ]  # fmt: skip
    remote, uncertainty, error = ctypes.c_double(), ctypes.c_double(), ctypes.c_int32()
    offset = function(inlet.obj, ctypes.byref(remote), ctypes.byref(uncertainty), timeout_s, ctypes.byref(error))
    lsl.util.handle_error(error)
    return offset, uncertainty.value


def describe_channels(info: Any, labels: tuple[str, ...], units: tuple[str, ...]) -> None:
    """Label and unit every channel in an LSL StreamInfo's description, as XDF readers expect."""
    channels = info.desc().append_child("channels")
    for label, unit in zip(labels, units):
        channel = channels.append_child("channel")
        channel.append_child_value("label", label)
        channel.append_child_value("unit", unit)


def pose_outlet(name: str, rate_hz: float, source_id: str) -> Any:
    """An outlet of a pose stream as `lsl:NAME` reads one (type "MoCap", `CHANNELS`), stamped by its pusher."""
    lsl = pylsl()
    info = lsl.StreamInfo(name, "MoCap", len(CHANNELS), rate_hz, lsl.cf_double64, source_id)
    describe_channels(info, CHANNELS, CHANNEL_UNITS)
    return lsl.StreamOutlet(info)


def lsl_origin(clock: Clock) -> float:
    """The LSL clock's reading at the rig clock's zero: LSL's clock is the system's monotonic clock."""
    return monotonic_origin_ns(clock) / NS_PER_S


class LslSampleDecoder:
    """Readings of the LSL reader's chunks, one sample each: (LSL stamp, px, py, pz, qw, qx, qy, qz).
    Nothing arrives damaged: liblsl checks what it carries."""

    corrupt = 0

    def feed_chunks(self, chunks: Sequence[tuple[float, ...]], arrivals: Sequence[float]) -> Readings:
        return Readings(list(arrivals), list(map(_STAMP, chunks)), None, list(map(_POSITION, chunks)), list(map(_ORIENTATION, chunks)))

    def reset(self) -> None:
        """Nothing: a sample is never partial."""


class LslTransport:
    """The inlet of the LSL stream called `name`, its clock corrections queued on `mapping`."""

    def __init__(self, name: str, mapping: CorrectedMapping) -> None:
        self.name = name
        self.description = f"LSL stream {name!r}"
        self.mapping = mapping
        self.source_id = ""
        self._inlet: Any = None
        self._origin_ns = 0
        self._next_correction = 0.0

    def _now(self) -> float:
        return (time.monotonic_ns() - self._origin_ns) / NS_PER_S

    def open(self, origin_ns: int) -> None:
        if LslReader is None:
            raise RigError(READER_MISSING)
        lsl = pylsl()
        streams = resolve_streams(RESOLVE_TIMEOUT_S, self.name)
        if not streams:
            raise RigError(f"no LSL stream named {self.name!r} answered within {RESOLVE_TIMEOUT_S:g} s; `rig devices` lists the streams it sees")
        info = streams[0]
        if info.channel_count() != len(CHANNELS):
            raise ConfigError(
                f"LSL stream {self.name!r} has {info.channel_count()} channels; a pose stream has {len(CHANNELS)}: "
                f"{', '.join(CHANNELS)} (metres, then a unit quaternion w first)"
            )
        self.source_id = info.source_id()
        inlet = lsl.StreamInlet(info, max_buflen=BUFFER_S, recover=True)
        try:
            # The first correction takes a good fraction of a second: measured before the samples flow.
            correction, uncertainty = time_correction(inlet, CORRECTION_TIMEOUT_S)
            open_inlet(inlet, OPEN_TIMEOUT_S)
        except (lsl.util.TimeoutError, lsl.util.LostError) as error:
            raise RigError(f"LSL stream {self.name!r} did not answer: {error}") from None
        self._origin_ns = origin_ns
        if self.mapping.origin_s is None:
            self.mapping.origin_s = origin_ns / NS_PER_S  # LSL's clock is the system's monotonic clock
        self.mapping.queue(correction, uncertainty, self._now())
        self._next_correction = self._now() + CORRECTION_INTERVAL_S
        self._inlet = inlet

    def reader(self) -> Reader:
        """The open inlet pulled on a compiled thread, which holds the inlet until it is joined."""
        inlet = self._inlet
        pull = ctypes.cast(pylsl().lib.lib.lsl_pull_sample_d, ctypes.c_void_p).value
        return LslReader(pull, inlet.obj.value, len(CHANNELS), self._origin_ns, inlet)

    def upkeep(self) -> None:
        """A fresh clock correction every CORRECTION_INTERVAL_S (liblsl's latest, without asking it to
        wait), queued for the consumer."""
        inlet, now = self._inlet, self._now()
        if inlet is None or now < self._next_correction:
            return
        self._next_correction = now + CORRECTION_INTERVAL_S
        lsl = pylsl()
        try:
            self.mapping.queue(*time_correction(inlet, 0.0), now)
        except (lsl.util.TimeoutError, lsl.util.LostError):
            pass  # no fresh estimate yet (liblsl measures in the background), or the sender is gone: the mapping keeps the last

    def close(self) -> None:
        inlet, self._inlet = self._inlet, None
        if inlet is not None:
            inlet.close_stream()


def lsl_tracker(address: str) -> TrackerStream:
    """An unconnected LSL tracker for the stream called `address`."""
    if not address:
        raise ConfigError("an LSL tracker needs the stream's name: lsl:NAME (`rig devices` lists the streams)")
    mapping = CorrectedMapping()
    transport = LslTransport(address, mapping)
    return TrackerStream(
        f"lsl:{address}",
        transport,
        LslSampleDecoder(),
        mapping,
        unit_tolerance=DEFAULT_UNIT_TOLERANCE,
        sequence_bits=None,
        describe=lambda: {"lsl": {"name": address, "source_id": transport.source_id, "channels": list(CHANNELS)}},
    )
