"""Tracker records fuzzed: whatever bytes a device sends, in whatever pieces, every shipped
profile's decoder returns readings or counts damage, never raises; records the emulator encodes
come back as the values sent, to the precision of the format."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rig.devices.trackers.decoders import decoder_for
from rig.devices.trackers.profile import POSITION, load_profile
from rig.emulate.encode import Emission, RecordEncoder

PROFILES = ("binary-pose", "csv", "hid-quat16", "polhemus-ascii", "polhemus-quat")
# What each format keeps of a value: text formats print a few decimals, hid-quat16 keeps 16 bits.
POSITION_TOLERANCE_M = 1e-3
ORIENTATION_TOLERANCE = 1e-3


def _pieces(data: bytes, cuts: list[int]) -> list[bytes]:
    bounds = sorted({min(cut, len(data)) for cut in cuts} | {0, len(data)})
    return [data[a:b] for a, b in zip(bounds, bounds[1:])]


@pytest.mark.parametrize("name", PROFILES)
@settings(max_examples=60)
@given(data=st.binary(max_size=600), cuts=st.lists(st.integers(0, 600), max_size=8))
def test_any_bytes_decode_to_readings_or_counted_damage(name: str, data: bytes, cuts: list[int]) -> None:
    decoder = decoder_for(load_profile(name))
    for piece in _pieces(data, cuts):
        readings = decoder.feed(piece, 1.0)
        assert all(len(position) == 3 for position in readings.positions)
        assert all(len(orientation) == 4 for orientation in readings.orientations)


unit_quaternion = st.tuples(*[st.floats(-1.0, 1.0)] * 4).filter(lambda q: sum(v * v for v in q) > 0.01).map(
    lambda q: tuple(v / math.sqrt(sum(u * u for u in q)) for v in q)
)
emission = st.builds(
    Emission,
    seq=st.integers(0, 255),
    device_time=st.floats(0.0, 60.0),
    position=st.tuples(*[st.floats(-1.0, 1.0)] * 3),
    orientation=unit_quaternion,
)


def _assert_decodes_to_what_was_sent(name: str, sent: Emission) -> None:
    profile = load_profile(name)
    readings = decoder_for(profile).feed(RecordEncoder(profile).encode(sent), 1.0)
    assert len(readings) == 1
    (position,), (orientation,) = readings.positions, readings.orientations
    if profile.has(*POSITION):
        assert position == pytest.approx(sent.position, abs=POSITION_TOLERANCE_M)
    same_sign = 1.0 if sum(a * b for a, b in zip(orientation, sent.orientation)) >= 0 else -1.0
    assert [same_sign * v for v in orientation] == pytest.approx(sent.orientation, abs=ORIENTATION_TOLERANCE)


@pytest.mark.parametrize("name", PROFILES)
@settings(max_examples=40)
@given(sent=emission)
def test_an_encoded_record_decodes_to_what_was_sent(name: str, sent: Emission) -> None:
    _assert_decodes_to_what_was_sent(name, sent)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_polhemus_record_at_gimbal_lock_decodes_to_the_orientation_sent(sign: float) -> None:
    """Elevation at +-90 degrees: the Euler angles are not unique, the rotation they make is."""
    half = math.sqrt(0.5)
    _assert_decodes_to_what_was_sent("polhemus-ascii", Emission(0, 0.0, (0.0, 0.0, 0.0), (half, 0.0, sign * half, 0.0)))
