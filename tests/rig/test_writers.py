"""Run records: tables readable row by row while they grow, with the exact values written."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from predictors import SAMPLE_COLUMNS, PoseSample, read_samples, sample_row
from rig.errors import RigError
from rig.writers import CsvRecord


def rows_of(path) -> list[list[str]]:
    with open(path, newline="") as stream:
        return list(csv.reader(stream))


def test_the_header_and_each_row_are_on_disk_as_soon_as_written(tmp_path) -> None:
    path = tmp_path / "frames.csv"
    record = CsvRecord(path, ["index", "t", "source"])
    try:
        assert rows_of(path) == [["index", "t", "source"]]
        record.write([0, 0.1, "modelled"])
        record.write([1, None, "measured"])
        assert rows_of(path)[1:] == [["0", "0.1", "modelled"], ["1", "", "measured"]]
        assert path.read_bytes().endswith(b"measured\n")
    finally:
        record.close()


def test_rows_left_to_the_caller_to_flush_reach_the_disk_at_each_flush(tmp_path) -> None:
    path = tmp_path / "events.csv"
    with CsvRecord(path, ["a"], flush_each_row=False) as record:
        record.write([1])
        record.write([2])
        record.flush()
        assert rows_of(path) == [["a"], ["1"], ["2"]]


def test_an_existing_file_is_replaced_only_when_asked(tmp_path) -> None:
    path = tmp_path / "t.csv"
    CsvRecord(path, ["a"]).close()
    with pytest.raises(RigError, match="already exists"):
        CsvRecord(path, ["a"])
    with CsvRecord(path, ["b"], overwrite=True) as record:
        record.write([3])
    assert rows_of(path) == [["b"], ["3"]]


def test_a_folder_that_does_not_exist_is_a_clear_error(tmp_path) -> None:
    with pytest.raises(RigError, match="cannot write .*nowhere"):
        CsvRecord(tmp_path / "nowhere" / "t.csv", ["a"])


def test_a_row_must_fill_the_header(tmp_path) -> None:
    with CsvRecord(tmp_path / "t.csv", ["a", "b"]) as record, pytest.raises(ValueError, match="2"):
        record.write([1])


def test_rows_of_numbers_written_in_bulk_must_fill_the_header_too(tmp_path) -> None:
    with CsvRecord(tmp_path / "t.csv", ["a", "b"]) as record, pytest.raises(ValueError, match="2"):
        record.write_numbers([(1.0, 2.0), (1.0,)])


cell = st.one_of(st.none(), st.floats(), st.integers(), st.floats(width=32).map(np.float32), st.floats().map(np.float64))


@given(rows=st.lists(st.lists(cell, min_size=3, max_size=3), max_size=5))
def test_rows_of_numbers_written_in_bulk_are_the_rows_written_one_by_one(tmp_path_factory, rows) -> None:
    folder = tmp_path_factory.mktemp("bulk")
    with CsvRecord(folder / "one.csv", ["a", "b", "c"]) as one, CsvRecord(folder / "bulk.csv", ["a", "b", "c"]) as bulk:
        for row in rows:
            one.write(row)
        bulk.write_numbers(rows)
    assert (folder / "bulk.csv").read_text() == (folder / "one.csv").read_text()
    assert bulk.rows == one.rows == len(rows)


finite = st.floats(allow_nan=False, allow_infinity=False)


@given(times=st.tuples(finite, finite), position=st.tuples(finite, finite, finite))
def test_tracker_samples_read_back_exactly(tmp_path_factory, times, position) -> None:
    sample = PoseSample(times[0], times[1], np.array(position), np.array([0.5, -0.5, 0.5, 0.5]))
    path = tmp_path_factory.mktemp("samples") / "tracker.csv"
    with CsvRecord(path, SAMPLE_COLUMNS) as record:
        record.write(sample_row(sample))
    (back,) = read_samples(path)
    assert (back.t_sensor, back.t_arrival) == (sample.t_sensor, sample.t_arrival)
    np.testing.assert_array_equal(back.position, sample.position)
    np.testing.assert_array_equal(back.orientation, sample.orientation)


def test_a_sample_file_cut_short_mid_row_keeps_every_whole_row(tmp_path) -> None:
    samples = [PoseSample(k / 100, k / 100 + 0.004, np.array([k * 0.01, 0.0, -1.0]), np.array([1.0, 0, 0, 0])) for k in range(5)]
    path = tmp_path / "tracker.csv"
    with CsvRecord(path, SAMPLE_COLUMNS) as record:
        for sample in samples:
            record.write(sample_row(sample))
    text = path.read_text()
    path.write_text(text[: text.rindex("\n", 0, -1) + 12])
    back = read_samples(path)
    assert [s.t_sensor for s in back] == [s.t_sensor for s in samples[:-1]]
    assert not math.isnan(back[-1].position[0])
