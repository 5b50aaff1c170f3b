"""`serial:URL`: a tracker on a serial line, a TCP socket or anything pyserial's `serial_for_url`
opens (/dev/ttyUSB0, socket://HOST:PORT, rfc2217://HOST:PORT, loop://).

    serial:/dev/ttyUSB0?profile=polhemus-ascii&baud=115200
    serial:socket://localhost:7777?profile=binary-pose

`profile` (a shipped profile's name or a .toml path; default csv) and `baud` (default 115200) are
the rig's; any other query option goes to pyserial with the URL.
"""

from __future__ import annotations

import errno
import logging
import os
import select
from functools import partial
from typing import Callable, Protocol
from urllib.parse import parse_qsl, urlencode

import serial

from rig.clock import Clock, MonotonicClock
from rig.devices.trackers.clock_mapping import mapping_for
from rig.devices.trackers.decoders import BinaryDecoder, TextDecoder, decoder_for
from rig.devices.trackers.profile import Profile, load_profile
from rig.devices.trackers.readings import Readings
from rig.devices.trackers.link import LinkLost
from rig.devices.trackers.stream import TrackerStream
from rig.errors import ConfigError, RigError

try:
    from rig.devices.trackers._readers import FdReader, wait_read
except ImportError:
    FdReader = wait_read = None

log = logging.getLogger("rig.trackers")

DEFAULT_PROFILE = "csv"
DEFAULT_BAUD = 115200
READ_TIMEOUT_S = 0.05
READ_TIMEOUT_MS = round(READ_TIMEOUT_S * 1000)
# Most bytes taken from a port with a file descriptor in one read.
CHUNK_BYTES = 65536
FD_READER_MISSING = (
    "rig.devices.trackers._readers is not built, so serial ports are waited on and read through Python: "
    "the same records, at more CPU per record; to build it, reinstall the package (pip install -e .)"
)


class SerialPort(Protocol):
    """What a tracker needs of a pyserial port."""


    @property
    def in_waiting(self) -> int: ...

    def read(self, size: int = 1) -> bytes: ...

    def close(self) -> None: ...


def open_serial_url(url: str, baud: int) -> SerialPort:
    """The default opener: pyserial's serial_for_url."""
    return serial.serial_for_url(url, baudrate=baud, timeout=READ_TIMEOUT_S)


def parse_serial_address(address: str) -> tuple[str, str, int]:
    """(pyserial URL, profile, baud rate) from `URL[?profile=NAME&baud=N&...]`."""
    url, _, query = address.partition("?")
    options = dict(parse_qsl(query, keep_blank_values=True))
    profile = options.pop("profile", DEFAULT_PROFILE)
    baud_text = options.pop("baud", str(DEFAULT_BAUD))
    if not url:
        raise ConfigError("a serial tracker needs a port: serial:/dev/ttyUSB0, serial:socket://HOST:PORT, serial:loop://")
    if not baud_text.isdigit() or int(baud_text) <= 0:
        raise ConfigError(f"baud={baud_text!r} in serial:{address}; expected a positive whole number such as 115200")
    if options:
        url = f"{url}?{urlencode(options)}"
    return url, profile, int(baud_text)


def _file_descriptor(port: SerialPort) -> int | None:
    """The port's file descriptor where it has one (a device, a pty, a socket), else None (loop://)."""
    try:
        return port.fileno()  # type: ignore[attr-defined]
    except (AttributeError, NotImplementedError, serial.SerialException, OSError):
        return None


def waiting_reader(fd: int) -> Callable[[int, int], bytes | None]:
    """`read(timeout_ms, size)` for `fd`: waits up to timeout_ms for it to be readable and reads what
    it holds, up to `size` bytes; None if nothing came in time, b"" at its end, OSError as os.read.
    The compiled `_readers.wait_read` where it is built, else a poll object registered once."""
    if wait_read is not None:
        return partial(wait_read, fd)
    poller = select.poll()
    poller.register(fd, select.POLLIN)

    def read(timeout_ms: int, size: int) -> bytes | None:
        return os.read(fd, size) if poller.poll(timeout_ms) else None

    return read


def _open_problem(url: str, error: Exception) -> RigError:
    code = getattr(error, "errno", None)
    if code == errno.EACCES:
        return RigError(
            f"no permission to open {url}: add your user to the group that owns it (often dialout: "
            "sudo usermod -aG dialout $USER, then log in again)"
        )
    if code == errno.ENOENT:
        return RigError(f"no serial port {url}: check the cable; `rig devices` lists the ports it sees")
    return RigError(f"cannot open the tracker's serial port {url}: {error}")


class SerialLink:
    """A pyserial port read through the profile's decoder. A port with a file descriptor (a device, a
    pty, a socket; pyserial keeps no buffer of its own for these) is waited on and read straight
    from the descriptor, whatever it holds: pyserial's socket handler counts a waiting socket as one
    byte, which would make reads byte by byte, and its read loop costs more than the decoding. On
    the system's monotonic clock a compiled thread does that (`native_reader`), without waking
    the interpreter per record; on another clock (a test's) the stream's Python thread does, one
    compiled wait and read per wake-up (`waiting_reader`). Others (loop://, rfc2217://) are read
    through pyserial with its timeout."""

    def __init__(self, url: str, baud: int, profile: Profile, open_port: Callable[[str, int], SerialPort]) -> None:
        self.url = url
        self.baud = baud
        self.description = f"serial {url} at {baud} baud"
        self._open_port = open_port
        self._decoder: TextDecoder | BinaryDecoder = decoder_for(profile)  # type: ignore[assignment]
        self._port: SerialPort | None = None
        self._fd: int | None = None
        self._read: Callable[[int, int], bytes | None] | None = None

    @property
    def corrupt(self) -> int:
        return self._decoder.corrupt

    def open(self, clock: Clock) -> None:
        try:
            port = self._open_port(self.url, self.baud)
        except (serial.SerialException, OSError, ValueError) as error:
            raise _open_problem(self.url, error) from None
        fd = _file_descriptor(port)
        self._read = None if fd is None else waiting_reader(fd)
        self._fd = fd
        self._port = port

    def native_reader(self, clock: Clock) -> FdReader | None:
        """The open port's descriptor read on a compiled thread, where it has one, the reader is
        built and the stamps can be on `clock` (the system's monotonic clock, which C reads too)."""
        if FdReader is None or self._fd is None or not (isinstance(clock, MonotonicClock) and clock.on_system_clock):
            return None
        return FdReader(self._fd, clock.origin_ns)

    def upkeep(self, clock: Clock) -> None:
        """Nothing: the device's clock is mapped from its records alone."""

    def receive(self, clock: Clock) -> bytes | None:
        port = self._port
        if port is None:
            raise LinkLost("the port is closed")
        try:
            if self._read is not None:
                data = self._read(READ_TIMEOUT_MS, CHUNK_BYTES)
                if data is None:
                    return None
                if not data:
                    raise LinkLost("the port reports data but returned none (disconnected)")
            else:
                data = port.read(max(1, port.in_waiting))
        except (serial.SerialException, OSError, TypeError, ValueError) as error:
            # pyserial raises TypeError when close() takes the port away in the middle of a read.
            raise LinkLost(str(error)) from None
        return data or None

    def decode(self, chunks: list[bytes], arrivals: list[float]) -> Readings:
        return self._decoder.feed_chunks(chunks, arrivals)

    def restart(self) -> None:
        self._decoder.reset()

    def close(self) -> None:
        port, self._port = self._port, None
        self._fd = None
        if port is not None:
            try:
                port.close()
            except (serial.SerialException, OSError):
                pass


def serial_tracker(address: str, open_port: Callable[[str, int], SerialPort] = open_serial_url) -> TrackerStream:
    """An unconnected serial tracker for `URL[?profile=...&baud=...]`."""
    url, profile_name, baud = parse_serial_address(address)
    profile = load_profile(profile_name)
    if FdReader is None:
        log.warning(FD_READER_MISSING)
    if profile.format == "hid":
        raise ConfigError(f"profile {profile.name} describes HID reports; a serial tracker needs a text or binary profile")
    return TrackerStream(
        f"serial:{address}",
        SerialLink(url, baud, profile, open_port),
        mapping_for(profile),
        unit_tolerance=profile.unit_tolerance,
        sequence_bits=profile.sequence_bits,
        describe=lambda: {"profile": profile.describe()},
    )
