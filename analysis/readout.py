"""A rolling shutter: the rows of a frame are exposed one after another, so each blob is filmed when
the readout reaches its rows.

A rolling-shutter camera (phones, webcams, most USB cameras) starts exposing row y of H at
t + (y / H) R, t the frame's time and R the readout, the time it takes to go from the top row to
the bottom one (a global shutter has R = 0). A blob whose centroid sits on row y is therefore seen
as it was (y / H) R after the frame's time, and where the sphere sits rows below the LED the
latency read from frame times is short by (row difference / H) R.

With the readout known, each blob's samples are dated by the rows they come from (``dated``: the
frame time plus the blob's centroid row / H x R, frame by frame), and every estimator works on
each blob's own times. Without it the readout is only bounded: a camera that films continuously
reads a frame out within a frame interval, so 0 <= R <= the median frame interval. The latency is
then measured on the frame times (R = 0) and the truth lies between it and it plus the largest bias
the blobs' rows allow, in the sign of their difference: later when the sphere is below the LED,
for rows read top to bottom (``widen``). The rows are each blob's mean, weighted by its speed
squared, which is how much each frame tells about timing.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from analysis.caveat import caveat
from analysis.errors import AnalysisError
from analysis.blobs import Track

# A given readout may exceed the median frame interval by this fraction (a camera's nominal rate
# against the timestamps) before it is refused.
READOUT_TOLERANCE = 0.05
# A widening smaller than this fraction of the interval's half-width, and than WIDENING_NOTICE_S,
# goes unsaid (as analysis.sampling's).
WIDENING_NOTICE = 0.25
WIDENING_NOTICE_S = 0.05e-3


@dataclass(frozen=True)
class RollingShutter:
    """What the camera's readout does to the latency.

    readout_s is the readout the user gave (source "given") or, unknown, the largest the frame rate
    allows (source "bounded"); frame_height the frame's rows; led_row and sphere_row the rows each
    blob's timing comes from (px from the top, weighted by speed squared).
    """

    readout_s: float
    source: str
    frame_height: int
    led_row: float
    sphere_row: float

    @property
    def row_time_s(self) -> float:
        """How much later each row down the blobs' samples are dated (s per row): the given readout's
        share of a row, 0 when it is only bounded (the samples keep the frame times)."""
        return self.readout_s / self.frame_height if self.source == "given" else 0.0

    @property
    def row_time_range_s(self) -> tuple[float, float]:
        """The range the camera's true time per row lies in (s per row)."""
        per_row = self.readout_s / self.frame_height
        return (per_row, per_row) if self.source == "given" else (0.0, per_row)

    @property
    def bias_bound_s(self) -> float:
        """By how much the truth may be later than a latency measured on these dates (s): the rows'
        difference times the time per row the dating left out, at most; negative when the sphere
        is above the LED (the truth may then be earlier), 0 for a given readout."""
        low, high = self.row_time_range_s
        return (self.sphere_row - self.led_row) * (high - self.row_time_s)

    def dated(self, track: Track) -> Track:
        """The track with each frame's time moved on by its centroid row times the time per row
        (rows interpolated over frames without the blob)."""
        if self.row_time_s == 0.0:
            return track
        frames = np.arange(track.t.size)
        rows = np.interp(frames, frames[track.valid], track.y[track.valid])
        return dataclasses.replace(track, t=track.t + rows * self.row_time_s)

    def widen(self, latency_s: float, ci_s: tuple[float, float] | None) -> tuple[float, float] | None:
        """The 95 % interval reaching out by the bias bound on its side."""
        if ci_s is None:
            return None
        bound = self.bias_bound_s
        return (ci_s[0] + min(bound, 0.0), ci_s[1] + max(bound, 0.0))

    def warning(self, ci_s: tuple[float, float] | None) -> str | None:
        """A warning naming the cause and the remedies when the bias bound widens the interval
        ``ci_s`` noticeably (see WIDENING_NOTICE), else None."""
        bound = self.bias_bound_s
        half_width = (ci_s[1] - ci_s[0]) / 2 if ci_s is not None else 0.0
        if abs(bound) <= max(WIDENING_NOTICE * half_width, WIDENING_NOTICE_S):
            return None
        where, later, longer = ("below", "later", "longer") if bound > 0 else ("above", "earlier", "shorter")
        return caveat(
            f"the sphere sits {abs(self.sphere_row - self.led_row):.0f} rows {where} the LED, so a rolling shutter may film "
            f"it up to {abs(bound) * 1e3:.2f} ms {later} than the LED: the latency may be that much {longer} than "
            "measured, and the interval was widened by it on that side",
            "film the LED at the sphere's height, give the camera's readout (--readout-ms; 0 for a global shutter), or "
            "measure it (rig calibrate-camera)",
        )

    def to_dict(self) -> dict[str, object]:
        return {
            "readout_ms": self.readout_s * 1e3,
            "readout_source": self.source,
            "frame_height": self.frame_height,
            "led_row": self.led_row,
            "sphere_row": self.sphere_row,
            "bias_bound_ms": self.bias_bound_s * 1e3,
        }


def weighted_row(track: Track) -> float:
    """The track's mean row (px), each frame weighted by the blob's speed squared (central
    differences between valid neighbours); the plain mean where it does not move."""
    valid = np.flatnonzero(track.valid)
    rows = track.y[valid]
    if valid.size < 3:
        return float(np.mean(rows)) if rows.size else math.nan
    t, x = track.t[valid], track.x[valid]
    dt = t[2:] - t[:-2]
    speed2 = ((x[2:] - x[:-2]) ** 2 + (rows[2:] - rows[:-2]) ** 2) / np.maximum(dt, 1e-12) ** 2
    total = float(speed2.sum())
    if not total > 0:
        return float(np.mean(rows))
    return float(speed2 @ rows[1:-1] / total)


def rolling_shutter(led: Track, sphere: Track, frame_height: int, readout_ms: float | None) -> RollingShutter:
    """The readout given (ms; 0 for a global shutter), or bounded by the median frame interval when
    None, with the rows each blob's timing comes from. AnalysisError for a given readout longer
    than a frame interval (a camera filming continuously cannot read a frame out more slowly)."""
    interval = float(np.median(np.diff(led.t)))
    if readout_ms is None:
        readout, source = interval, "bounded"
    else:
        readout, source = readout_ms / 1e3, "given"
        if readout > (1 + READOUT_TOLERANCE) * interval:
            raise AnalysisError(
                f"the readout {readout_ms:g} ms is longer than the frame interval ({interval * 1e3:.3g} ms); give the "
                "time the camera takes to read one frame from top to bottom, and check the frame rate (--fps)"
            )
    return RollingShutter(readout, source, frame_height, weighted_row(led), weighted_row(sphere))
