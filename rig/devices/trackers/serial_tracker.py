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
from typing import Callable, Protocol
from urllib.parse import parse_qsl, urlencode

import serial

from rig.devices.trackers.decoders import decoder_for
from rig.devices.trackers.default_profiles import SERIAL as DEFAULT_PROFILE
from rig.devices.trackers.profile import load_profile
from rig.devices.trackers.stream import TrackerStream, profile_stream
from rig.devices.trackers.transport import Reader, ThreadReader
from rig.errors import ConfigError, RigError

try:
    from rig.devices.trackers._readers import FdReader
except ImportError:
    FdReader = None

log = logging.getLogger("rig.trackers")

DEFAULT_BAUD = 115200
READ_TIMEOUT_S = 0.05
FD_READER_MISSING = (
    "rig.devices.trackers._readers is not built, so serial ports are read through pyserial in Python: "
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


class SerialTransport:
    """A pyserial port. One with a file descriptor (a device, a pty, a socket; pyserial keeps no
    buffer of its own for these) is read straight from the descriptor by the compiled `FdReader`,
    whatever it holds: pyserial's socket handler counts a waiting socket as one byte, which would
    make reads byte by byte, and its read loop costs more than the decoding. Others (loop://,
    rfc2217://) are read through pyserial, with its timeout, by a `ThreadReader`."""

    def __init__(self, url: str, baud: int, open_port: Callable[[str, int], SerialPort]) -> None:
        self.url = url
        self.baud = baud
        self.description = f"serial {url} at {baud} baud"
        self._open_port = open_port
        self._port: SerialPort | None = None
        self._origin_ns = 0

    def open(self, origin_ns: int) -> None:
        try:
            self._port = self._open_port(self.url, self.baud)
        except (serial.SerialException, OSError, ValueError) as error:
            raise _open_problem(self.url, error) from None
        self._origin_ns = origin_ns

    def reader(self) -> Reader:
        port = self._port
        fd = _file_descriptor(port)  # type: ignore[arg-type]
        if fd is not None and FdReader is not None:
            return FdReader(fd, self._origin_ns)
        return ThreadReader(lambda: port.read(max(1, port.in_waiting)) or None, self._origin_ns, f"serial reader {self.url}")  # type: ignore[union-attr]

    def upkeep(self) -> None:
        """Nothing: the device's clock is mapped from its records alone."""

    def close(self) -> None:
        port, self._port = self._port, None
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
    return profile_stream(f"serial:{address}", SerialTransport(url, baud, open_port), decoder_for(profile), profile)
