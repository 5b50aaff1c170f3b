"""Trace files fuzzed: whatever a file holds, reading it gives a trace or a PredictorError saying
what is wrong, never another exception; a trace written is read back exactly."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import PredictorError, Trace, read_trace
from predictors.trace import SAMPLE_COLUMNS, read_samples, write_trace

HEADERS = [",".join(SAMPLE_COLUMNS), "t,px,py,pz,qw,qx,qy,qz", "t,qw,qx,qy,qz,px,py,pz", "t_sensor,px,py"]
cell = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["", "nan", "-", "1e999", "0x10", " 1 ", "1,2", '"3"', "\x00"]),
    st.text(max_size=4),
)
csv_like = st.builds(
    lambda header, rows: header + "\n" + "\n".join(",".join(row) for row in rows),
    st.sampled_from(HEADERS) | st.text(max_size=30),
    st.lists(st.lists(cell, max_size=10), max_size=6),
)


def _read_both(path: Path) -> None:
    """Each reader refuses with PredictorError or gives what it promises: a trace of finite,
    time-ordered samples; samples of nine numbers each."""
    try:
        trace = read_trace(path)
    except PredictorError:
        pass
    else:
        assert trace.t.size > 0 and np.isfinite(trace.t).all() and (np.diff(trace.t) >= 0).all()
        assert np.isfinite(trace.position).all() and np.isfinite(trace.orientation).all()
    try:
        samples = read_samples(path)
    except PredictorError:
        pass
    else:
        assert all(sample.position.shape == (3,) and sample.orientation.shape == (4,) for sample in samples)


@settings(max_examples=150)
@given(text=csv_like)
def test_any_text_reads_as_a_trace_or_a_predictor_error(text: str, tmp_path_factory) -> None:
    path = tmp_path_factory.mktemp("trace") / "fuzzed.csv"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    _read_both(path)


@settings(max_examples=80)
@given(data=st.binary(max_size=400))
def test_any_bytes_read_as_a_trace_or_a_predictor_error(data: bytes, tmp_path_factory) -> None:
    path = tmp_path_factory.mktemp("trace") / "fuzzed.csv"
    path.write_bytes(data)
    _read_both(path)


@st.composite
def traces(draw: st.DrawFn) -> Trace:
    n = draw(st.integers(1, 20))
    steps = draw(st.lists(st.floats(1e-4, 0.1), min_size=n, max_size=n))
    t = np.cumsum(steps) + draw(st.floats(-10.0, 10.0))
    position = np.array(draw(st.lists(st.tuples(*[st.floats(-5.0, 5.0)] * 3), min_size=n, max_size=n)))
    angles = np.array(draw(st.lists(st.floats(-math.pi, math.pi), min_size=n, max_size=n)))
    orientation = np.column_stack([np.cos(angles / 2), np.sin(angles / 2), np.zeros(n), np.zeros(n)])
    delay = draw(st.floats(0.0, 0.05))
    return Trace.from_samples("fuzzed", t, position, orientation, t + delay)


@settings(max_examples=60)
@given(trace=traces())
def test_a_written_trace_reads_back_exactly(trace: Trace, tmp_path_factory) -> None:
    path = tmp_path_factory.mktemp("trace") / "round.csv"
    write_trace(path, trace)
    back = read_trace(path)
    np.testing.assert_array_equal(back.t, trace.t)
    np.testing.assert_array_equal(back.t_arrival, trace.t_arrival)
    np.testing.assert_array_equal(back.position, trace.position)
    np.testing.assert_array_equal(back.orientation, trace.orientation)
    assert len(read_samples(path)) == len(trace)
