"""The checks a binary tracker record may end with, each over the bytes between sync and check.

Each returns the check as the bytes the device sends (multi-byte checks in the record's byte order).
"""

from __future__ import annotations

import binascii
import zlib
from functools import reduce
from typing import Callable


def _xor8(data: bytes, _order: str) -> bytes:
    return bytes([reduce(lambda a, b: a ^ b, data, 0)])


def _sum8(data: bytes, _order: str) -> bytes:
    return bytes([sum(data) & 0xFF])


def _crc16_ccitt(data: bytes, order: str) -> bytes:
    """CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF), as the rig board's frames."""
    return binascii.crc_hqx(data, 0xFFFF).to_bytes(2, order)  # type: ignore[arg-type]


def _crc32(data: bytes, order: str) -> bytes:
    """CRC-32 as zlib, Ethernet and PNG compute it."""
    return zlib.crc32(data).to_bytes(4, order)  # type: ignore[arg-type]


def _none(_data: bytes, _order: str) -> bytes:
    return b""


CHECKSUMS: dict[str, Callable[[bytes, str], bytes]] = {
    "none": _none,
    "xor8": _xor8,
    "sum8": _sum8,
    "crc16-ccitt": _crc16_ccitt,
    "crc32": _crc32,
}
CHECK_BYTES = {"none": 0, "xor8": 1, "sum8": 1, "crc16-ccitt": 2, "crc32": 4}
