"""Tracker samples on disk, and traces: samples with the motion to score predictions against.

One file format holds tracker samples everywhere (what the rig records, simulated or live; what
benches, tuning and notebooks read): CSV with the header `t_sensor,t_arrival,px,py,pz,qw,qx,qy,qz`
(`SAMPLE_COLUMNS`: seconds on the rig clock, metres, unit quaternion w-first), one row per sample
in the order the host received them. The rig writes it row by row as samples arrive and ends every
row with a newline in the same write, so in such a file a last line without one is a row cut short
by a crash: readers skip it. Recordings from elsewhere read as traces too with a `t` column (the
sensor time) instead of `t_sensor`, and `t_arrival` optional (the sensor time when absent).

A `Trace` holds the samples a predictor is fed and the truth it is scored against. For a recording
the truth is the recording itself; `with_noise` and `with_delay` change the samples and leave the
truth as it was, so a predictor is scored against the clean motion.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from predictors import quaternion
from predictors.errors import PredictorError
from predictors.pose import PoseSample

POSE_COLUMNS = ("px", "py", "pz", "qw", "qx", "qy", "qz")
SAMPLE_COLUMNS = ("t_sensor", "t_arrival", *POSE_COLUMNS)
_NORM_TOLERANCE = 1e-3


def _sorted_unique(t: np.ndarray, position: np.ndarray, orientation: np.ndarray) -> tuple[np.ndarray, ...]:
    """Rows sorted by time, the last row of each repeated time kept (it arrived later)."""
    order = np.argsort(t, kind="stable")
    t, position, orientation = t[order], position[order], orientation[order]
    keep = np.append(t[1:] != t[:-1], True)
    return t[keep], position[keep], orientation[keep]


@dataclass(frozen=True, eq=False)
class Trace:
    """Samples (in file order) and the truth: times (N,), positions (N, 3), orientations (N, 4).

    truth_t is strictly increasing; the truth between its times is interpolated linearly in
    position and by slerp in orientation. Build one with `Trace.from_samples`, `read_trace`, or the
    generators in `predictors.synthetic`.
    """

    name: str
    t: np.ndarray
    t_arrival: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    truth_t: np.ndarray
    truth_position: np.ndarray
    truth_orientation: np.ndarray

    @classmethod
    def from_samples(
        cls,
        name: str,
        t: np.ndarray,
        position: np.ndarray,
        orientation: np.ndarray,
        t_arrival: np.ndarray | None = None,
    ) -> Trace:
        """A trace whose truth is its own samples (a recording)."""
        t, position, orientation = _checked(name, t, position, orientation)
        t_arrival = t.copy() if t_arrival is None else np.asarray(t_arrival, dtype=np.float64)
        if t_arrival.shape != t.shape or not np.isfinite(t_arrival).all():
            raise PredictorError(f"trace {name!r}: t_arrival must be {t.size} finite times")
        truth = _sorted_unique(t, position, orientation)
        return cls(name, t, t_arrival, position, orientation, *truth)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """Seconds from the first to the last sample."""
        return float(self.t.max() - self.t.min()) if len(self) else 0.0

    def arrival_order(self) -> np.ndarray:
        """Indices of the samples in the order the host received them (ties in file order)."""
        return np.argsort(self.t_arrival, kind="stable")

    def samples(self) -> list[PoseSample]:
        """The samples in the order the host received them."""
        return [
            PoseSample(float(self.t[i]), float(self.t_arrival[i]), self.position[i], self.orientation[i])
            for i in self.arrival_order()
        ]

    def with_samples(self, t: np.ndarray, t_arrival: np.ndarray, position: np.ndarray, orientation: np.ndarray) -> Trace:
        """Other samples (a simulated tracker's, say) scored against this trace's truth."""
        t, position, orientation = _checked(self.name, t, position, orientation)
        t_arrival = np.asarray(t_arrival, dtype=np.float64)
        if t_arrival.shape != t.shape or not np.isfinite(t_arrival).all():
            raise PredictorError(f"trace {self.name!r}: t_arrival must be {t.size} finite times")
        return replace(self, t=t, t_arrival=t_arrival, position=position, orientation=orientation)

    def order_faults(self) -> tuple[int, int]:
        """(samples earlier than the one before them, samples at the time of the one before them),
        by sensor time in file order: a recording's clock went back, or it logged a time twice."""
        steps = np.diff(self.t)
        return int(np.count_nonzero(steps < 0.0)), int(np.count_nonzero(steps == 0.0))

    def in_time_order(self) -> Trace:
        """The samples sorted by sensor time, each repeated time kept once (the last one in the
        file, as the truth keeps it); arrival times travel with their samples."""
        order = np.argsort(self.t, kind="stable")
        t = self.t[order]
        keep = order[np.append(t[1:] != t[:-1], True)]
        return replace(self, t=self.t[keep], t_arrival=self.t_arrival[keep], position=self.position[keep],
                       orientation=self.orientation[keep])

    def covers(self, times: np.ndarray) -> np.ndarray:
        """Which times lie within the truth's time span."""
        return (times >= self.truth_t[0]) & (times <= self.truth_t[-1])

    def truth_at(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The true positions (..., 3) and orientations (..., 4) at `times`, clamped to the truth's span."""
        times = np.clip(np.asarray(times, dtype=np.float64), self.truth_t[0], self.truth_t[-1])
        if self.truth_t.size == 1:
            shape = times.shape
            return (
                np.broadcast_to(self.truth_position[0], shape + (3,)).copy(),
                np.broadcast_to(self.truth_orientation[0], shape + (4,)).copy(),
            )
        i = np.clip(np.searchsorted(self.truth_t, times, side="right") - 1, 0, self.truth_t.size - 2)
        t0, t1 = self.truth_t[i], self.truth_t[i + 1]
        u = (times - t0) / (t1 - t0)
        p0, p1 = self.truth_position[i], self.truth_position[i + 1]
        position = p0 + u[..., None] * (p1 - p0)
        orientation = quaternion.slerp(self.truth_orientation[i], self.truth_orientation[i + 1], u)
        return position, orientation

    def between(self, start: float, end: float) -> Trace:
        """The samples with start <= t < end, and the truth over the same span."""
        keep = (self.t >= start) & (self.t < end)
        truth = (self.truth_t >= start) & (self.truth_t < end)
        if not keep.any() or not truth.any():
            raise PredictorError(
                f"trace {self.name!r} has no samples in [{start:g}, {end:g}) s; it spans "
                f"[{self.t.min():g}, {self.t.max():g}] s"
            )
        return replace(
            self,
            t=self.t[keep],
            t_arrival=self.t_arrival[keep],
            position=self.position[keep],
            orientation=self.orientation[keep],
            truth_t=self.truth_t[truth],
            truth_position=self.truth_position[truth],
            truth_orientation=self.truth_orientation[truth],
        )

    def split(self, fraction: float) -> tuple[Trace, Trace]:
        """The first `fraction` of the trace's duration and the rest, as (train, held-out)."""
        if not 0.0 < fraction < 1.0:
            raise PredictorError(f"a split fraction must be between 0 and 1, got {fraction!r}")
        cut = float(self.t.min()) + fraction * self.duration
        first = self.between(-math.inf, cut)
        rest = self.between(cut, math.inf)
        return replace(first, name=f"{self.name}[:{fraction:g}]"), replace(rest, name=f"{self.name}[{fraction:g}:]")

    def resampled(self, rate_hz: float) -> Trace:
        """Samples at a uniform rate (Hz) over the same span, interpolated from the truth (so
        resample first, then add noise)."""
        if not (math.isfinite(rate_hz) and rate_hz > 0.0):
            raise PredictorError(f"a resampling rate must be a positive number of Hz, got {rate_hz!r}")
        t = self.truth_t[0] + np.arange(int(math.floor(self.duration * rate_hz)) + 1) / rate_hz
        position, orientation = self.truth_at(t)
        return replace(self, t=t, t_arrival=t.copy(), position=position, orientation=orientation)

    def with_noise(self, position_std_m: float, orientation_std_rad: float, seed: int) -> Trace:
        """Samples with Gaussian noise added (per axis; orientation as a small body-frame rotation)."""
        if not (position_std_m >= 0.0 and orientation_std_rad >= 0.0):
            raise PredictorError("noise standard deviations must be zero or positive")
        rng = np.random.default_rng(seed)
        n = len(self)
        position = self.position + position_std_m * rng.standard_normal((n, 3))
        turn = quaternion.from_rotation_vector(orientation_std_rad * rng.standard_normal((n, 3)))
        orientation = quaternion.normalise(quaternion.multiply(self.orientation, turn))
        return replace(self, position=position, orientation=orientation)

    def with_delay(self, delay_s: float) -> Trace:
        """Samples that reach the host delay_s seconds later (predictions are asked at arrival)."""
        if not (math.isfinite(delay_s) and delay_s >= 0.0):
            raise PredictorError(f"a delay must be zero or a positive number of seconds, got {delay_s!r}")
        return replace(self, t_arrival=self.t_arrival + delay_s)


def _checked(name: str, t: np.ndarray, position: np.ndarray, orientation: np.ndarray) -> tuple[np.ndarray, ...]:
    t = np.asarray(t, dtype=np.float64)
    position = np.asarray(position, dtype=np.float64)
    orientation = np.asarray(orientation, dtype=np.float64)
    n = t.size
    if t.ndim != 1 or n == 0 or position.shape != (n, 3) or orientation.shape != (n, 4):
        raise PredictorError(
            f"trace {name!r}: expected times (N,), positions (N, 3) and orientations (N, 4) with N > 0, "
            f"got {t.shape}, {position.shape}, {orientation.shape}"
        )
    finite = np.isfinite(t) & np.isfinite(position).all(axis=1) & np.isfinite(orientation).all(axis=1)
    norm = np.linalg.norm(orientation, axis=1)
    bad = ~finite | (np.abs(norm - 1.0) > _NORM_TOLERANCE)
    if bad.any():
        row = int(np.argmax(bad))
        raise PredictorError(
            f"trace {name!r}, sample {row}: every value must be finite and the quaternion of unit norm "
            f"(within {_NORM_TOLERANCE:g}), got t={float(t[row])!r}, norm {float(norm[row])!r}"
        )
    return t, position, orientation / norm[:, None]


def sample_row(sample: PoseSample) -> tuple[float, ...]:
    """The values of one sample in `SAMPLE_COLUMNS` order."""
    return (sample.t_sensor, sample.t_arrival, *sample.position.tolist(), *sample.orientation.tolist())


def _table(path: Path, what: str) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """The header and the numbered, non-empty rows of a CSV file; in a file of the rig's own format, a
    last row without its newline (cut short by a crash) is left out."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise PredictorError(f"cannot read {what} {path}: {error}") from None
    lines = text.split("\n")
    header = [name.strip() for name in next(csv.reader([lines[0]]))] if lines[0] else []
    if header[:1] == ["t_sensor"]:
        lines = lines[:-1]
    rows = [(number, row) for number, row in enumerate(csv.reader(lines[1:]), start=2) if row]
    return header, rows


def read_samples(path: str | os.PathLike[str]) -> list[PoseSample]:
    """The samples of a file in the rig's format (`SAMPLE_COLUMNS`), in file order, exactly as
    written; PredictorError naming the line of a malformed row."""
    path = Path(path)
    header, rows = _table(path, "tracker samples from")
    if tuple(header) != SAMPLE_COLUMNS:
        raise PredictorError(f"{path} is not a tracker sample file: its first line must be {','.join(SAMPLE_COLUMNS)}")
    samples = []
    for number, row in rows:
        try:
            if len(row) != len(SAMPLE_COLUMNS):
                raise ValueError(f"expected {len(SAMPLE_COLUMNS)} comma-separated numbers, got {len(row)}")
            values = [float(cell) for cell in row]
            samples.append(PoseSample(values[0], values[1], np.array(values[2:5]), np.array(values[5:9])))
        except (ValueError, PredictorError) as error:
            raise PredictorError(f"{path}, line {number}: {error}") from None
    return samples


def read_trace(path: str | os.PathLike[str]) -> Trace:
    """A trace from a CSV file (see the module docstring); PredictorError naming what is wrong."""
    path = Path(path)
    header, rows = _table(path, "trace")
    if not header:
        raise PredictorError(f"trace {path} is empty; it needs the header {','.join(SAMPLE_COLUMNS)}")
    time_column = "t" if "t" in header else "t_sensor"
    missing = [c for c in (time_column, *POSE_COLUMNS) if c not in header]
    if missing:
        raise PredictorError(
            f"trace {path} lacks column(s) {', '.join(missing)}; the header must hold "
            f"{','.join(SAMPLE_COLUMNS)} (or t instead of t_sensor, and t_arrival optional)"
        )
    columns = [header.index(c) for c in (time_column, *POSE_COLUMNS)]
    arrival = header.index("t_arrival") if "t_arrival" in header else None
    body = [row for _, row in rows]
    try:
        values = np.array([[float(row[c]) for c in columns] for row in body], dtype=np.float64)
        t_arrival = None if arrival is None else np.array([float(row[arrival]) for row in body])
    except (ValueError, IndexError):
        raise PredictorError(f"trace {path}: every row must hold {len(header)} numbers") from None
    if values.size == 0:
        raise PredictorError(f"trace {path} has a header but no samples")
    return Trace.from_samples(path.stem, values[:, 0], values[:, 1:4], values[:, 4:8], t_arrival)


def write_trace(path: str | os.PathLike[str], trace: Trace) -> None:
    """Write the trace's samples in the rig's format (`SAMPLE_COLUMNS`), in the trace's order;
    floats round-trip exactly."""
    with open(path, "w", newline="", encoding="utf-8") as file:
        file.write(",".join(SAMPLE_COLUMNS) + "\n")
        for row in np.column_stack([trace.t, trace.t_arrival, trace.position, trace.orientation]):
            file.write(",".join(repr(float(v)) for v in row) + "\n")
