"""Frames of the board protocol: COBS byte stuffing, CRC-16/CCITT-FALSE, and a stream decoder that
counts and skips every bad frame instead of failing (see protocol.h)."""

from __future__ import annotations

import binascii
from dataclasses import dataclass, field

from rig.board.protocol import ProtocolSpec

_CRC_POLY_OF_CRC_HQX = 0x1021


class FrameError(ValueError):
    """A frame that cannot be decoded; the decoder counts these, nobody else sees them."""


def crc16(data: bytes, spec: ProtocolSpec) -> int:
    """CRC-16/CCITT-FALSE of `data`, the frame check of the protocol."""
    if spec["RIG_CRC16_POLY"] != _CRC_POLY_OF_CRC_HQX:
        raise ValueError(f"binascii.crc_hqx computes polynomial 0x1021, the header asks {spec['RIG_CRC16_POLY']:#x}")
    return binascii.crc_hqx(data, spec["RIG_CRC16_INIT"])


def cobs_encode(data: bytes) -> bytes:
    """`data` without zero bytes: each block of up to 254 non-zero bytes is prefixed by its length + 1,
    and a block shorter than 254 stands for the zero that ended it."""
    out = bytearray([0])
    code_at = 0
    for byte in data:
        if byte == 0:
            out[code_at] = len(out) - code_at
            code_at = len(out)
            out.append(0)
            continue
        out.append(byte)
        if len(out) - code_at == 0xFF:
            out[code_at] = 0xFF
            code_at = len(out)
            out.append(0)
    out[code_at] = len(out) - code_at
    return bytes(out)


def cobs_decode(data: bytes) -> bytes:
    """Inverse of cobs_encode; raises FrameError on a zero byte or a block running past the end."""
    out = bytearray()
    index = 0
    while index < len(data):
        code = data[index]
        end = index + code
        if code == 0 or end > len(data):
            raise FrameError("bad COBS block")
        block = data[index + 1 : end]
        if 0 in block:
            raise FrameError("zero byte inside a COBS frame")
        out += block
        index = end
        if code != 0xFF and index < len(data):
            out.append(0)
    return bytes(out)


def encode_frame(message_type: int, seq: int, payload: bytes, spec: ProtocolSpec) -> bytes:
    """A frame ready for the wire, delimiter included."""
    if len(payload) > spec["RIG_FRAME_MAX_PAYLOAD"]:
        raise ValueError(f"payload of {len(payload)} bytes is over RIG_FRAME_MAX_PAYLOAD")
    raw = bytes((message_type, seq & 0xFF)) + payload
    raw += crc16(raw, spec).to_bytes(spec["RIG_FRAME_CRC_BYTES"], "little")
    return cobs_encode(raw) + bytes((spec["RIG_FRAME_DELIMITER"],))


@dataclass(frozen=True)
class Frame:
    type: int
    seq: int
    payload: bytes


@dataclass
class LinkCounters:
    """What the decoder saw on the line: good frames; frames that failed COBS or the CRC, were too
    short or too long; good frames of a type (or payload length) this side does not accept; and
    frames missing from the sender's sequence numbers, which includes those that arrived corrupt."""

    frames: int = 0
    corrupt: int = 0
    truncated: int = 0
    oversize: int = 0
    unknown: int = 0
    lost: int = 0


@dataclass
class FrameDecoder:
    """Turns received bytes into frames of the accepted types (by default the RIG_MSG_ types a
    board sends); anything else is counted and dropped."""

    spec: ProtocolSpec
    accepted_prefix: str = "RIG_MSG_"
    counters: LinkCounters = field(default_factory=LinkCounters)
    _pending: bytearray = field(default_factory=bytearray)
    _oversize: bool = False
    _next_seq: int | None = None

    def reset(self) -> None:
        """Forget a partial frame and the sequence: the line was reopened."""
        self._pending.clear()
        self._oversize = False
        self._next_seq = None

    def feed(self, data: bytes) -> list[Frame]:
        frames: list[Frame] = []
        delimiter = self.spec["RIG_FRAME_DELIMITER"]
        limit = self.spec["RIG_FRAME_MAX_ENCODED"] - 1
        start = 0
        while True:
            end = data.find(delimiter, start)
            chunk = data[start:] if end < 0 else data[start:end]
            if len(self._pending) + len(chunk) > limit:
                self._oversize = True
                self._pending.clear()
            else:
                self._pending += chunk
            if end < 0:
                return frames
            frame = self._complete()
            if frame is not None:
                frames.append(frame)
            start = end + 1

    def _complete(self) -> Frame | None:
        encoded = bytes(self._pending)
        oversize = self._oversize
        self._pending.clear()
        self._oversize = False
        if oversize:
            self.counters.oversize += 1
            return None
        if not encoded:
            return None
        try:
            raw = cobs_decode(encoded)
        except FrameError:
            self.counters.corrupt += 1
            return None
        header = self.spec["RIG_FRAME_HEADER_BYTES"]
        check = self.spec["RIG_FRAME_CRC_BYTES"]
        if len(raw) < header + check:
            self.counters.truncated += 1
            return None
        if crc16(raw[:-check], self.spec) != int.from_bytes(raw[-check:], "little"):
            self.counters.corrupt += 1
            return None
        frame = Frame(type=raw[0], seq=raw[1], payload=raw[header:-check])
        if self._next_seq is not None:
            self.counters.lost += (frame.seq - self._next_seq) % 256
        self._next_seq = (frame.seq + 1) % 256
        name = self.spec.type_names.get(frame.type, "")
        if not name.startswith(self.accepted_prefix) or len(frame.payload) != self.spec.layout(frame.type).size:
            self.counters.unknown += 1
            return None
        self.counters.frames += 1
        return frame
