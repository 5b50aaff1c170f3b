"""The checks a binary tracker record may end with, each over the bytes between sync and check.

`CHECK_VALUES` gives a check as the number the record carries (its `CHECK_CODES` struct code in the
record's byte order reads it back, so a decoder compares numbers); `CHECKSUMS` as the bytes the
device sends (multi-byte checks in the record's byte order).
"""

from __future__ import annotations

import binascii
import zlib
from functools import partial, reduce
from operator import xor
from typing import Callable


def _xor8(data: bytes) -> int:
    return reduce(xor, data, 0)


def _sum8(data: bytes) -> int:
    return sum(data) & 0xFF


def _crc16_ccitt(data: bytes) -> int:
    """CRC-16/CCITT-FALSE (polynomial 0x1021, initial 0xFFFF), as the rig board's frames."""
    return binascii.crc_hqx(data, 0xFFFF)


CHECK_VALUES: dict[str, Callable[[bytes], int] | None] = {
    "none": None,
    "xor8": _xor8,
    "sum8": _sum8,
    "crc16-ccitt": _crc16_ccitt,
    "crc32": zlib.crc32,  # as zlib, Ethernet and PNG compute it
}
CHECK_CODES = {"none": "", "xor8": "B", "sum8": "B", "crc16-ccitt": "H", "crc32": "I"}
CHECK_BYTES = {"none": 0, "xor8": 1, "sum8": 1, "crc16-ccitt": 2, "crc32": 4}


def _check_bytes(name: str, data: bytes, order: str) -> bytes:
    value = CHECK_VALUES[name]
    return b"" if value is None else value(data).to_bytes(CHECK_BYTES[name], order)  # type: ignore[arg-type]


CHECKSUMS: dict[str, Callable[[bytes, str], bytes]] = {name: partial(_check_bytes, name) for name in CHECK_VALUES}
