"""The one file format of tracker samples: read exactly, and malformed files named line by line."""

from __future__ import annotations

import numpy as np
import pytest

from predictors import SAMPLE_COLUMNS, PredictorError, read_samples, read_trace

HEADER = ",".join(SAMPLE_COLUMNS)


@pytest.mark.parametrize(
    "text, message",
    [
        ("t,x,y\n", "not a tracker sample file"),
        ("", "not a tracker sample file"),
        (HEADER + "\n0,0,0,0,0,1,0,0\n", "line 2: expected 9 comma-separated numbers, got 8"),
        (HEADER + "\n0,0,0,0,0,1,0,0,0\n0,0,0,0,zero,1,0,0,0\n", "line 3: could not convert"),
        (HEADER + "\n0,0,0,0,0,2,0,0,0\n", "line 2: .*unit quaternion"),
    ],
)
def test_reading_a_malformed_file_names_the_problem(tmp_path, text, message) -> None:
    path = tmp_path / "tracker.csv"
    path.write_text(text)
    with pytest.raises(PredictorError, match=message):
        read_samples(path)


def test_reading_a_missing_file_raises(tmp_path) -> None:
    with pytest.raises(PredictorError, match="cannot read tracker samples"):
        read_samples(tmp_path / "absent.csv")


def test_a_recording_reads_as_a_trace_in_its_own_order(tmp_path) -> None:
    path = tmp_path / "tracker.csv"
    path.write_text(HEADER + "\n0.0,0.004,0,0,-1,1,0,0,0\n0.01,0.014,0.1,0,-1,1,0,0,0\n")
    trace = read_trace(path)
    np.testing.assert_array_equal(trace.t, [0.0, 0.01])
    np.testing.assert_array_equal(trace.t_arrival, [0.004, 0.014])
    assert [s.t_sensor for s in read_samples(path)] == [0.0, 0.01]


def test_a_recording_from_elsewhere_without_a_final_newline_keeps_its_last_row(tmp_path) -> None:
    path = tmp_path / "head.csv"
    path.write_text("t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.5,0,0,0,1,0,0,0")
    assert len(read_trace(path)) == 2
