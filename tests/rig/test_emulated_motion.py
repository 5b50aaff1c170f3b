"""The emulated tracker's motion: a pose for every sample it is asked to send."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rig.emulate.motion import Motion


def test_a_short_slow_stream_has_a_pose_for_its_last_sample() -> None:
    # 200 Hz for 1 s: the last sample's block of 1000 reaches 5 s, past the old window of 3 s.
    motion = Motion(200.0, 1.0)
    position, orientation, _ = motion.pose(200)
    assert all(map(math.isfinite, (*position, *orientation)))


@settings(max_examples=15, deadline=None)
@given(rate_hz=st.floats(30.0, 2000.0), duration_s=st.floats(0.05, 6.0))
def test_every_sample_of_a_stream_has_a_pose(rate_hz: float, duration_s: float) -> None:
    motion = Motion(rate_hz, duration_s)
    for k in (0, math.ceil(duration_s * rate_hz)):
        _, orientation, _ = motion.pose(k)
        assert abs(math.fsum(q * q for q in orientation) - 1.0) < 1e-9
