"""Decoders fed transcripts (tests/rig/devices/transcripts): chunks as a serial reader queued them,
with their arrivals, decode to the readings the device's manual says they hold, each stamped with
the arrival of the chunk that completed it, the damage counted where it was."""

from __future__ import annotations

import ast
import math
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from rig.devices.trackers.decoders import decoder_for
from rig.devices.trackers.profile import load_profile

TRANSCRIPTS = Path(__file__).parent / "transcripts"
HALF = math.sqrt(0.5)


def _transcript(name: str, chunk_of: Callable[[str], bytes]) -> tuple[list[bytes], list[float]]:
    """(chunks, arrivals) of a transcript: one chunk a line, its arrival (s) first."""
    lines = [line.split(" ", 1) for line in (TRANSCRIPTS / name).read_text().splitlines() if line and not line.startswith("#")]
    return [chunk_of(chunk) for _, chunk in lines], [float(arrival) for arrival, _ in lines]


def test_a_binary_transcript_gives_its_intact_records_across_cuts_wraps_and_damage() -> None:
    chunks, arrivals = _transcript("binary-pose-damaged.txt", bytes.fromhex)
    decoder = decoder_for(load_profile("binary-pose"))
    readings = decoder.feed_chunks(chunks, arrivals)
    assert readings.seqs == [65534, 0, 1, 2]
    assert readings.arrivals == [10.000, 10.002, 10.003, 10.004]
    assert readings.device_times == pytest.approx([4294.965, 4294.967, 4294.968, 4294.969], abs=1e-9)
    assert readings.positions == [(0.0, -0.5, 1.0), (0.5, -0.5, 1.0), (0.75, -0.5, 1.0), (1.0, -0.5, 1.0)]
    assert readings.orientations == [(1.0, 0.0, 0.0, 0.0), pytest.approx((1.0, 0.0, 0.0, 0.0)), pytest.approx((HALF, 0.0, 0.0, HALF)), (1.0, 0.0, 0.0, 0.0)]
    assert readings.discarded == {1: 1, 2: 1}, "the damaged record before seq 0, the garbage before seq 1"
    assert decoder.corrupt == 2


def test_a_text_transcript_gives_its_lines_in_metres_and_quaternions() -> None:
    chunks, arrivals = _transcript("polhemus-ascii-lines.txt", ast.literal_eval)
    decoder = decoder_for(load_profile("polhemus-ascii"))
    readings = decoder.feed_chunks(chunks, arrivals)
    assert readings.arrivals == [20.000, 20.001, 20.002]
    np.testing.assert_allclose(readings.positions, [(0.3048, -0.0762, 0.127), (0.3048, -0.0762, 0.127), (0.0, 0.0, 0.0)], atol=1e-12)
    np.testing.assert_allclose(readings.orientations, [(HALF, 0.0, 0.0, HALF), (HALF, 0.0, HALF, 0.0), (0.0, 1.0, 0.0, 0.0)], atol=1e-12)
    assert readings.device_times is None
    assert readings.discarded == {2: 1} and decoder.corrupt == 1
