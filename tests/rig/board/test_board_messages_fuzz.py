"""Board frames fuzzed past the framing: a board whose firmware sends well-framed messages of any
type, sequence and payload (right CRC, wrong everything else) gives events or nothing, never an
exception on the reader thread; a message packed from its fields unpacks to the same fields."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rig.board.events import BoardEvent
from rig.board.framing import FrameDecoder, encode_frame
from rig.board.messages import MessageReader
from rig.board.protocol import protocol

SPEC = protocol()
MESSAGE_TYPES = sorted(value for value, name in SPEC.type_names.items() if name.startswith("RIG_MSG_"))


@settings(max_examples=300)
@given(st.lists(st.tuples(st.integers(0, 255), st.integers(0, 255), st.binary(max_size=24)), max_size=12))
def test_well_framed_messages_of_any_content_give_events_or_nothing(messages: list[tuple[int, int, bytes]]) -> None:
    decoder = FrameDecoder(SPEC)
    reader = MessageReader(lambda board_time: board_time + 100.0)
    wire = b"".join(encode_frame(kind, seq, payload, SPEC) for kind, seq, payload in messages)
    for frame in decoder.feed(wire):
        event = reader.event(frame.type, SPEC.layout(frame.type).unpack(frame.payload))
        assert event is None or isinstance(event, BoardEvent)
        if event is not None:
            assert math.isfinite(event.board_time)


@settings(max_examples=100)
@given(st.sampled_from(MESSAGE_TYPES), st.integers(0, 255), st.data())
def test_fields_packed_into_a_frame_unpack_to_the_same_fields(message_type: int, seq: int, data: st.DataObject) -> None:
    layout = SPEC.layout(message_type)
    payload = data.draw(st.binary(min_size=layout.size, max_size=layout.size))
    fields = layout.unpack(payload)
    frames = FrameDecoder(SPEC).feed(encode_frame(message_type, seq, layout.pack(**fields), SPEC))
    assert [(frame.type, frame.seq, layout.unpack(frame.payload)) for frame in frames] == [(message_type, seq, fields)]
