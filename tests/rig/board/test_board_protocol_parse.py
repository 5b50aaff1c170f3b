"""Reading the protocol from protocol.h, the firmware's header shipped in rig.board
(tests/firmware/test_protocol_header.py checks the parse against the C compiler)."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.board.blink_code import LFSR_TAPS
from analysis.board.recording import TICK_HZ
from rig.board.protocol import HEADER_FILE, parse_protocol_header, protocol
from rig.errors import RigError

HEADER = """
#define RIG_FRAME_MAX_PAYLOAD 8 /* a comment */
#define RIG_NAME "rig" // another
#define RIG_HEX 0x1Fu
#define RIG_LONG 2000000UL
#define RIG_PACKED __attribute__((packed))
#define RIG_MSG_PAIR 0x81
#define RIG_CMD_PING 0x01
typedef struct RIG_PACKED {
	uint8_t small; /* one byte */
	int32_t big;
	char tag[3];
} rig_msg_pair_t;
"""


def test_synthetic_header_is_read() -> None:
    spec = parse_protocol_header(HEADER)
    assert spec["RIG_HEX"] == 31 and spec["RIG_LONG"] == 2_000_000
    assert spec.strings == {"RIG_NAME": "rig"}
    assert "RIG_PACKED" not in spec.constants
    pair = spec.layout(0x81)
    assert (pair.name, pair.fields, pair.format, pair.size) == ("rig_msg_pair_t", ("small", "big", "tag"), "<Bi3s", 8)
    assert spec.layout(0x01).size == 0
    assert spec.type_names == {0x81: "RIG_MSG_PAIR", 0x01: "RIG_CMD_PING"}


def test_payloads_pack_and_unpack() -> None:
    pair = parse_protocol_header(HEADER).layout(0x81)
    payload = pair.pack(small=7, big=-5, tag=b"abc")
    assert pair.unpack(payload) == {"small": 7, "big": -5, "tag": b"abc"}
    with pytest.raises(ValueError, match="needs the fields"):
        pair.pack(small=1, big=2)
    with pytest.raises(ValueError):
        pair.pack(small=256, big=0, tag=b"")
    with pytest.raises(ValueError, match="expected 8"):
        pair.unpack(payload[:-1])


@pytest.mark.parametrize(
    ("header", "message"),
    [
        (HEADER.replace("rig_msg_pair_t", "rig_msg_other_t"), "no message type"),
        (HEADER.replace("int32_t big", "float big"), "cannot read the field"),
        (HEADER.replace("int32_t big;", "int32_t big[2];"), "only char fields"),
        (HEADER.replace("RIG_CMD_PING 0x01", "RIG_CMD_PING 0x81"), "share a number"),
        (HEADER.replace("RIG_FRAME_MAX_PAYLOAD 8", "RIG_FRAME_MAX_PAYLOAD 4"), "longer than RIG_FRAME_MAX_PAYLOAD"),
    ],
)
def test_malformed_headers_are_rejected(header: str, message: str) -> None:
    with pytest.raises(RigError, match=message):
        parse_protocol_header(header)


def test_real_header_defines_every_message_the_link_uses() -> None:
    spec = protocol()
    assert protocol() is spec
    assert HEADER_FILE.name == "protocol.h"
    for name in ("IDENTIFY", "SYNC", "STATUS", "LED", "BLINK", "ENCODER", "PHOTODIODE", "STREAM"):
        assert spec.type_id(f"RIG_CMD_{name}") in spec.layouts
    for name in ("ACK", "IDENTITY", "SYNC", "SYNC_SENT", "STATUS", "ENCODER", "CROSSING", "PASSAGE", "SAMPLE", "LED"):
        assert spec.layout(spec.type_id(f"RIG_MSG_{name}")).size <= spec["RIG_FRAME_MAX_PAYLOAD"]
    assert spec.status_name(spec["RIG_STATUS_BAD_VALUE"]) == "bad value"
    with pytest.raises(KeyError):
        spec.type_id("RIG_TICK_HZ")


def test_the_packaged_header_is_the_firmwares() -> None:
    firmware_header = Path(__file__).resolve().parents[3] / "firmware" / "include" / "protocol.h"
    assert HEADER_FILE.read_bytes() == firmware_header.read_bytes()


def test_the_analysis_library_reads_recordings_with_the_headers_values() -> None:
    """analysis.board cannot read the header (it never imports rig), so it states the two values it
    needs; they must be the header's."""
    spec = protocol()
    assert TICK_HZ == spec["RIG_TICK_HZ"]
    assert LFSR_TAPS == spec["RIG_BLINK_LFSR_TAPS"]
