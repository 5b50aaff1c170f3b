"""The simulated tracker, and the CSV file format that tracker samples are recorded in.

The simulated sensor rides on the pendulum bob. It measures at a fixed rate on its own clock and
sends each measurement over a serial/USB-like transport:

* t_sensor = t_start + phase_s + k / rate_hz, for every k with t_sensor < t_end;
* the position gets independent Gaussian noise, position_noise_m per axis;
* the orientation gets a random small rotation in the sensor (body) frame: a rotation vector with
  independent Gaussian components of orientation_noise_deg, applied as q_true * q_noise;
* t_arrival = t_sensor + transport_delay_s + jitter, the jitter exponentially distributed with
  mean jitter_s (a transport is sometimes late, never early);
* the transport never reorders: a sample that would overtake its predecessor arrives with it,
  so t_arrival is non-decreasing;
* each sample is lost with probability `dropout`, independently.

All randomness comes from numpy's default_rng(seed), drawn for every sample in a fixed order, so a
seed fixes the whole run and changing the dropout rate does not change the noise of the samples
that are kept.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

import numpy as np
from scipy.spatial.transform import Rotation

from predictors import PoseSample
from rig.errors import ConfigError, RigError
from rig.sim.pendulum import Pendulum

CSV_HEADER = "t_sensor,t_arrival,px,py,pz,qw,qx,qy,qz"
_CSV_FIELDS = len(CSV_HEADER.split(","))


@dataclass(frozen=True)
class TrackerConfig:
    """Rate, noise and transport of a simulated tracker. Times in seconds, noise as std-devs."""

    rate_hz: float = 120.0
    position_noise_m: float = 0.0002
    orientation_noise_deg: float = 0.05
    transport_delay_s: float = 0.004
    jitter_s: float = 0.0005
    dropout: float = 0.0
    phase_s: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0.0):
            raise ConfigError(
                f"TrackerConfig.rate_hz must be a positive finite rate in Hz, got {self.rate_hz!r}"
            )
        for name in ("position_noise_m", "orientation_noise_deg", "transport_delay_s", "jitter_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"TrackerConfig.{name} must be a finite number >= 0, got {value!r}")
        if not (0.0 <= self.dropout < 1.0):
            raise ConfigError(f"TrackerConfig.dropout must be a probability in [0, 1), got {self.dropout!r}")
        if not (0.0 <= self.phase_s < 1.0 / self.rate_hz):
            raise ConfigError(
                f"TrackerConfig.phase_s must be in [0, 1 / rate_hz) = [0, {1.0 / self.rate_hz!r}) s, "
                f"got {self.phase_s!r}"
            )


def simulate_tracker(
    pendulum: Pendulum, config: TrackerConfig, t_start: float, t_end: float, seed: int
) -> list[PoseSample]:
    """The samples a tracker on `pendulum` delivers for sensor times in [t_start, t_end).

    Sorted by t_arrival (which, as the transport keeps order, is also t_sensor order).
    """
    if not (math.isfinite(t_start) and math.isfinite(t_end) and t_end > t_start):
        raise ConfigError(f"simulate_tracker needs t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    if t_start < pendulum.t_start or t_end > pendulum.t_end:
        raise ConfigError(
            f"the tracker window [{t_start!r}, {t_end!r}] s is not inside the pendulum's "
            f"[{pendulum.t_start!r}, {pendulum.t_end!r}] s; simulate the pendulum over a longer window"
        )
    count = math.ceil((t_end - t_start - config.phase_s) * config.rate_hz) + 1
    t_sensor = t_start + config.phase_s + np.arange(count) / config.rate_hz
    t_sensor = t_sensor[t_sensor < t_end]
    n = t_sensor.size

    rng = np.random.default_rng(seed)
    position_noise = config.position_noise_m * rng.standard_normal((n, 3))
    rotation_noise = math.radians(config.orientation_noise_deg) * rng.standard_normal((n, 3))
    jitter = config.jitter_s * rng.standard_exponential(n)
    kept = rng.random(n) >= config.dropout

    positions, orientations = pendulum.sensor_pose(t_sensor)
    positions = positions + position_noise
    measured = Rotation.from_quat(orientations, scalar_first=True) * Rotation.from_rotvec(rotation_noise)
    orientations = measured.as_quat(scalar_first=True)
    orientations /= np.linalg.norm(orientations, axis=1, keepdims=True)

    t_sensor, positions, orientations = t_sensor[kept], positions[kept], orientations[kept]
    t_arrival = np.maximum.accumulate(t_sensor + config.transport_delay_s + jitter[kept])
    return [
        PoseSample(float(ts), float(ta), p, q)
        for ts, ta, p, q in zip(t_sensor, t_arrival, positions, orientations)
    ]


def _csv_row(sample: PoseSample) -> str:
    values = (sample.t_sensor, sample.t_arrival, *sample.position.tolist(), *sample.orientation.tolist())
    return ",".join(repr(float(v)) for v in values) + "\n"


class TrackerCsvWriter:
    """Writes tracker samples to CSV as they arrive, one flushed row per sample.

    Each row is flushed to the operating system at once, so a crash of the recording process
    leaves a readable file holding every sample written so far (a power cut may still lose the
    last rows: rows are flushed, not fsynced). Floats are written with repr, so reading the file
    gives back the exact values. An existing file is only replaced with overwrite=True.
    """

    def __init__(self, path: str | os.PathLike[str], overwrite: bool = False) -> None:
        self.path = Path(path)
        try:
            self._file = open(self.path, "w" if overwrite else "x", encoding="ascii", newline="")
        except FileExistsError:
            raise RigError(
                f"{self.path} already exists; choose another file or pass overwrite=True to replace it"
            ) from None
        except OSError as error:
            raise RigError(f"cannot write tracker samples to {self.path}: {error.strerror}") from None
        self._file.write(CSV_HEADER + "\n")
        self._file.flush()

    def write(self, sample: PoseSample) -> None:
        """Append one sample and flush it."""
        self._file.write(_csv_row(sample))
        self._file.flush()

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> TrackerCsvWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()


def write_tracker_csv(
    path: str | os.PathLike[str], samples: list[PoseSample], overwrite: bool = False
) -> None:
    """Write all `samples` to a new tracker CSV file (see TrackerCsvWriter)."""
    with TrackerCsvWriter(path, overwrite=overwrite) as writer:
        for sample in samples:
            writer.write(sample)


def read_tracker_csv(path: str | os.PathLike[str]) -> list[PoseSample]:
    """Read a tracker CSV file written by TrackerCsvWriter, in file order.

    The writer ends every row with a newline in the same write, so a last line without one is a
    row cut short by a crash mid-write: it is skipped. Any other malformed row raises RigError
    naming the line.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="ascii")
    except (OSError, UnicodeDecodeError) as error:
        raise RigError(f"cannot read tracker samples from {path}: {error}") from None
    lines = text.split("\n")
    if lines[0] != CSV_HEADER:
        raise RigError(f"{path} is not a tracker CSV file: its first line must be {CSV_HEADER!r}")
    samples = []
    for number, row in enumerate(lines[1:-1], start=2):
        try:
            samples.append(_parse_row(row))
        except ValueError as error:
            raise RigError(f"{path}, line {number}: {error}") from None
    return samples


def _parse_row(row: str) -> PoseSample:
    fields = row.split(",")
    if len(fields) != _CSV_FIELDS:
        raise ValueError(f"expected {_CSV_FIELDS} comma-separated numbers, got {len(fields)}")
    values = [float(field) for field in fields]
    return PoseSample(values[0], values[1], np.array(values[2:5]), np.array(values[5:9]))
