"""`lsl:NAME`: a pose stream on Lab Streaming Layer, as motion capture systems and game engines
publish them: 7 channels, position in metres (px, py, pz) then a unit quaternion w first (qw, qx,
qy, qz), each sample stamped on the sender's LSL clock.

The sender's stamps are mapped onto the rig clock with liblsl's own clock offset, measured by round
trips (`lsl_time_correction_ex`, which gives the offset's uncertainty beside it; pylsl exposes only
the offset) and refreshed every CORRECTION_INTERVAL_S on the reading side (the stream's thread,
never the consumer's: liblsl's answer can wait on the network, and the consumer may be a render
loop), so the tracker's latency to the host is known. On the system's monotonic clock the inlet
is pulled by a compiled thread (`_readers.LslReader`, calling liblsl's `lsl_pull_sample_d` as
pylsl loaded it); elsewhere by the stream's Python thread. The inlet recovers a sender that restarts (same source
id) by itself. pylsl is imported only when an LSL stream is used or listed, and liblsl's own
console log is kept to fatal errors: the rig logs what happens to the link itself.
"""

from __future__ import annotations

import ctypes
from collections import deque
from itertools import chain, repeat
from operator import itemgetter
from types import ModuleType
from typing import Any

from rig.clock import Clock, MonotonicClock
from rig.devices.trackers.clock_mapping import CorrectedMapping
from rig.devices.trackers.profile import DEFAULT_UNIT_TOLERANCE
from rig.devices.trackers.readings import Readings
from rig.devices.trackers.link import LinkLost
from rig.devices.trackers.stream import TrackerStream
from rig.errors import ConfigError, RigError

try:
    from rig.devices.trackers._readers import LslReader
except ImportError:
    LslReader = None

CHANNELS = ("px", "py", "pz", "qw", "qx", "qy", "qz")
_POSITION, _ORIENTATION = itemgetter(0, 1, 2), itemgetter(3, 4, 5, 6)
RESOLVE_TIMEOUT_S = 2.0
OPEN_TIMEOUT_S = 2.0
READ_TIMEOUT_S = 0.05
CORRECTION_INTERVAL_S = 1.0
CORRECTION_TIMEOUT_S = 2.0
# Seconds of samples the inlet buffers while the reader is busy: far more than it ever is.
BUFFER_S = 30
_LIBLSL_CONFIG = "[log]\nlevel = -3\n"
_pylsl: ModuleType | None = None


def pylsl() -> ModuleType:
    """pylsl, imported on first use with liblsl's console log kept to fatal errors."""
    global _pylsl
    if _pylsl is None:
        import pylsl as module

        module.set_config_content(_LIBLSL_CONFIG)
        _pylsl = module
    return _pylsl


def time_correction(inlet: Any, timeout_s: float) -> tuple[float, float]:
    """(offset, uncertainty) in seconds: local time = the sender's time + offset, within +-uncertainty."""
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


class SamplePuller:
    """`inlet.pull_sample` without pylsl's per-call Python (the argument objects it builds, its error
    handler, its list): liblsl's `lsl_pull_sample_d` into a buffer made once, the timeout too. The
    reader thread calls it once per wake-up, once per sample at 1000 Hz; liblsl converts any
    numeric channel format to double."""

    def __init__(self, inlet: Any, timeout_s: float) -> None:
        lsl = pylsl()
        self._pull = lsl.lib.lib.lsl_pull_sample_d
        self._available = lsl.lib.lib.lsl_samples_available
        self._handle_error = lsl.util.handle_error
        self._inlet = inlet  # kept alive while its handle is used
        self._handle = inlet.obj
        self._values = (ctypes.c_double * len(CHANNELS))()
        self._timeout = ctypes.c_double(timeout_s)
        self._error = ctypes.c_int32()
        self._error_ref = ctypes.byref(self._error)

    def pull(self) -> tuple[list[float], float] | None:
        """The next sample and its stamp, waiting up to the timeout; None if none came. LostError
        when the sender is gone, as pylsl raises it."""
        stamp = self._pull(self._handle, self._values, len(CHANNELS), self._timeout, self._error_ref)
        if self._error.value:
            self._handle_error(self._error.value)
        return (self._values[:], stamp) if stamp else None

    def waiting(self) -> int:
        """Samples the inlet holds now."""
        return self._available(self._handle)


def lsl_origin(clock: Clock) -> float:
    """The LSL clock's reading at the rig clock's zero. LSL's clock is the system's monotonic clock,
    the same as a MonotonicClock's; another clock is assumed to run at its rate."""
    if isinstance(clock, MonotonicClock):
        return clock.origin_ns / 1e9
    return pylsl().local_clock() - clock.now()


class LslLink:
    """The inlet of the LSL stream called `name`. What its readers queue is (samples, their LSL
    stamps): several samples a chunk from the Python reader, one from the compiled one."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.description = f"LSL stream {name!r}"
        self.corrupt = 0
        self.mapping = CorrectedMapping()
        self.source_id = ""
        self._inlet: Any = None
        self._puller: SamplePuller | None = None
        self._next_correction = 0.0
        self._corrections: deque[tuple[float, float, float]] = deque()
        """Corrections measured on the reading side, (offset, uncertainty, rig time), for the consumer
        to hand the mapping with the samples, on the thread that maps them."""

    def open(self, clock: Clock) -> None:
        lsl = pylsl()
        streams = lsl.resolve_byprop("name", self.name, timeout=RESOLVE_TIMEOUT_S)
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
            inlet.open_stream(timeout=OPEN_TIMEOUT_S)
        except (lsl.util.TimeoutError, lsl.util.LostError) as error:
            raise RigError(f"LSL stream {self.name!r} did not answer: {error}") from None
        if self.mapping.origin_s is None:
            self.mapping.origin_s = lsl_origin(clock)
        self._corrections.append((correction, uncertainty, clock.now()))
        self._next_correction = clock.now() + CORRECTION_INTERVAL_S
        self._puller = SamplePuller(inlet, READ_TIMEOUT_S)
        self._inlet = inlet

    def native_reader(self, clock: Clock) -> LslReader | None:
        """The open inlet pulled on a compiled thread, where the reader is built and the stamps can
        be on `clock` (the system's monotonic clock, which C reads too); it holds the inlet until
        its thread is joined."""
        inlet = self._inlet
        if LslReader is None or inlet is None or not (isinstance(clock, MonotonicClock) and clock.on_system_clock):
            return None
        pull = ctypes.cast(pylsl().lib.lib.lsl_pull_sample_d, ctypes.c_void_p).value
        return LslReader(pull, inlet.obj.value, len(CHANNELS), clock.origin_ns, inlet)

    def receive(self, clock: Clock) -> tuple[list, list] | None:
        """(samples, their LSL stamps), or None if nothing came in time."""
        lsl = pylsl()
        inlet, puller = self._inlet, self._puller
        if inlet is None or puller is None:
            raise LinkLost("the inlet is closed")
        self.upkeep(clock)
        try:
            pulled = puller.pull()
            if pulled is None:
                return None
            first, stamp = pulled
            # A chunk pull allocates buffers for its largest size: asked only for what is waiting.
            waiting = puller.waiting()
            rest, stamps = inlet.pull_chunk(timeout=0.0, max_samples=waiting) if waiting else ([], [])
        except lsl.util.LostError as error:
            raise LinkLost(f"the sender is gone ({error})") from None
        return [first, *rest], [stamp, *stamps]

    def decode(self, chunks: list[tuple[list, list]], arrivals: list[float]) -> Readings:
        """The chunks' samples; first the clock corrections measured since the last call go to the
        mapping, on this (the consumer's) thread."""
        corrections, add = self._corrections, self.mapping.add_correction
        while corrections:
            add(*corrections.popleft())
        samples = list(chain.from_iterable(map(itemgetter(0), chunks)))
        stamps = list(chain.from_iterable(map(itemgetter(1), chunks)))
        times = list(chain.from_iterable(map(repeat, arrivals, map(len, map(itemgetter(1), chunks)))))
        return Readings(times, stamps, None, list(map(_POSITION, samples)), list(map(_ORIENTATION, samples)))

    def upkeep(self, clock: Clock) -> None:
        """A fresh clock correction every CORRECTION_INTERVAL_S (liblsl's latest, without asking it to
        wait), queued for the consumer."""
        inlet, now = self._inlet, clock.now()
        if inlet is None or now < self._next_correction:
            return
        self._next_correction = now + CORRECTION_INTERVAL_S
        lsl = pylsl()
        try:
            self._corrections.append((*time_correction(inlet, 0.0), now))
        except (lsl.util.TimeoutError, lsl.util.LostError):
            pass  # no fresh estimate yet (liblsl measures in the background), or the sender is gone: the mapping keeps the last

    def restart(self) -> None:
        pass

    def close(self) -> None:
        inlet, self._inlet = self._inlet, None
        self._puller = None
        if inlet is not None:
            inlet.close_stream()


def lsl_tracker(address: str) -> TrackerStream:
    """An unconnected LSL tracker for the stream called `address`."""
    if not address:
        raise ConfigError("an LSL tracker needs the stream's name: lsl:NAME (`rig devices` lists the streams)")
    link = LslLink(address)
    return TrackerStream(
        f"lsl:{address}",
        link,
        link.mapping,
        unit_tolerance=DEFAULT_UNIT_TOLERANCE,
        sequence_bits=None,
        describe=lambda: {"lsl": {"name": address, "source_id": link.source_id, "channels": list(CHANNELS)}},
    )
