"""Frames of the board protocol: COBS, CRC and the stream decoder that skips bad frames."""

from __future__ import annotations

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from rig.board.framing import FrameDecoder, FrameError, cobs_decode, cobs_encode, crc16, encode_frame
from rig.board.protocol import protocol

SPEC = protocol()
MESSAGE_TYPES = sorted(value for value, name in SPEC.type_names.items() if name.startswith("RIG_MSG_"))


def payload_of(message_type: int, pattern: bytes) -> bytes:
    """A payload of the right length for the type, repeating `pattern`."""
    size = SPEC.layout(message_type).size
    return (pattern * size)[:size]


@given(st.binary(max_size=700))
@example(b"")
@example(bytes(300))
@example(b"\x01" * 254)
@example(b"\x01" * 254 + b"\x00")
@example(b"\x01" * 508)
def test_cobs_round_trip_has_no_zero_bytes(data: bytes) -> None:
    encoded = cobs_encode(data)
    assert 0 not in encoded
    assert len(encoded) <= len(data) + len(data) // 254 + 1
    assert cobs_decode(encoded) == data


@pytest.mark.parametrize("bad", [b"\x00", b"\x05\x01\x02", b"\x03\x01\x00"])
def test_cobs_rejects_malformed_blocks(bad: bytes) -> None:
    with pytest.raises(FrameError):
        cobs_decode(bad)


def test_crc_is_ccitt_false() -> None:
    assert crc16(b"123456789", SPEC) == 0x29B1
    assert crc16(b"", SPEC) == SPEC["RIG_CRC16_INIT"]


@given(st.sampled_from(MESSAGE_TYPES), st.integers(0, 255), st.binary(min_size=1, max_size=8))
def test_every_message_type_survives_the_wire(message_type: int, seq: int, seed: bytes) -> None:
    payload = payload_of(message_type, seed)
    decoder = FrameDecoder(SPEC)
    frames = decoder.feed(encode_frame(message_type, seq, payload, SPEC))
    assert [(f.type, f.seq, f.payload) for f in frames] == [(message_type, seq, payload)]
    assert decoder.counters.frames == 1


def test_byte_by_byte_feeding_gives_the_same_frames() -> None:
    wire = b"".join(encode_frame(SPEC["RIG_MSG_LED"], seq, bytes([seq, 0, 0, 0, 255, 0, 0]), SPEC) for seq in range(20))
    whole = FrameDecoder(SPEC).feed(wire)
    decoder = FrameDecoder(SPEC)
    pieces = [frame for byte in wire for frame in decoder.feed(bytes([byte]))]
    assert pieces == whole and len(whole) == 20


def test_every_single_bit_error_is_caught() -> None:
    wire = encode_frame(SPEC["RIG_MSG_ENCODER"], 7, bytes(range(1, 12)), SPEC)
    for bit in range(8 * (len(wire) - 1)):
        damaged = bytearray(wire)
        damaged[bit // 8] ^= 1 << (bit % 8)
        assert FrameDecoder(SPEC).feed(bytes(damaged)) == []


def test_truncated_oversize_unknown_and_wrong_length_frames_are_counted() -> None:
    decoder = FrameDecoder(SPEC)
    raw = bytes((SPEC["RIG_MSG_ACK"],))
    wire = cobs_encode(raw) + b"\x00"  # one byte: no room for seq and CRC
    wire += b"\x42" * 60 + b"\x00"  # longer than any frame
    wire += encode_frame(0x7E, 1, b"", SPEC)  # good CRC, no such type
    wire += encode_frame(SPEC["RIG_CMD_STATUS"], 2, b"", SPEC)  # a command: not for the host
    wire += encode_frame(SPEC["RIG_MSG_ACK"], 3, b"\x01", SPEC)  # ACK with 1 byte instead of 3
    wire += b"\x00\x00"  # idle line
    wire += encode_frame(SPEC["RIG_MSG_ACK"], 4, b"\x01\x02\x00", SPEC)
    frames = decoder.feed(wire)
    assert [f.seq for f in frames] == [4]
    counters = decoder.counters
    assert (counters.truncated, counters.oversize, counters.unknown, counters.corrupt) == (1, 1, 3, 0)


def test_sequence_gaps_count_lost_frames_and_reset_forgets_them() -> None:
    decoder = FrameDecoder(SPEC)
    ack = b"\x01\x02\x00"
    for seq in (250, 251, 254, 1):
        decoder.feed(encode_frame(SPEC["RIG_MSG_ACK"], seq, ack, SPEC))
    assert decoder.counters.lost == 2 + 2
    decoder.reset()
    decoder.feed(encode_frame(SPEC["RIG_MSG_ACK"], 100, ack, SPEC))
    assert decoder.counters.lost == 4


@given(st.binary(max_size=300))
def test_noise_never_raises_and_a_frame_after_it_gets_through(noise: bytes) -> None:
    decoder = FrameDecoder(SPEC)
    decoder.feed(noise)
    frame = encode_frame(SPEC["RIG_MSG_ACK"], 9, b"\x05\x11\x00", SPEC)
    frames = decoder.feed(b"\x00" + frame)
    assert [(f.seq, f.payload) for f in frames][-1:] == [(9, b"\x05\x11\x00")]
