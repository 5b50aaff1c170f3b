"""A board recording as the camera path's reference: `rig analyse VIDEO --board DIR`.

The recording (`rig board record --blink`) holds the LED's blink code (led.csv) and the encoder at
the pivot (encoder.csv), both on the board's clock. The video shows the blink: the analyser's LED
track keeps every frame's peak brightness, even where no blob is found, and a frame counts as lit
when that peak exceeds LIT_FRACTION of the LED's typical peak. `align_blink_code` then gives
board time = video time + offset. On the video's clock the encoder says when the pendulum left
rest; `analysis.onset` measures that departure from the encoder's angle exactly as it does from
the LED's track, so the sphere's departure minus the encoder's is the latency with no whole number
of periods left open (``analysis.cycles``). The encoder is timed to microseconds and sees the
release even while the LED blinks.

A frame's time stamp is taken as the start of its exposure and the exposure as the whole frame
interval (so each frame samples the LED half an interval after its stamp); a shorter exposure only
narrows the true offset inside the interval reported. The departure needs none of that precision:
candidates are a whole period apart.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from analysis.onset import departure_time
from analysis.blobs import Track
from analysis.board.blink_code import BlinkAlignment, align_blink_code
from analysis.board.photodiode_latency import EncoderTrajectory, encoder_trajectory
from analysis.board.recording import ENCODER, LED, load_table
from analysis.errors import AnalysisError

EVENT_NAME = "board encoder start"
LIT_FRACTION = 0.5
# The encoder's angle is sampled this often on the video's clock to find its departure.
ENCODER_SAMPLE_S = 1e-3


@dataclass
class BoardReference:
    """A board recording, and what it told about one video once `departures` has run."""

    recording: Path
    led_times: np.ndarray
    led_levels: np.ndarray
    encoder: EncoderTrajectory
    alignment: BlinkAlignment | None = None
    departure_board_s: float | None = None

    @classmethod
    def load(cls, recording: Path) -> BoardReference:
        led = load_table(recording, LED.name)
        encoder = load_table(recording, ENCODER.name)
        if led["board_time_s"].size < 2:
            raise AnalysisError(f"{recording}/led.csv holds no blink: record with `rig board record --blink`")
        if encoder["board_time_s"].size < 2:
            raise AnalysisError(f"{recording}/encoder.csv holds no encoder edges: did the pendulum swing while recording?")
        trajectory = encoder_trajectory(encoder["board_time_s"], encoder["count"], encoder["step"])
        return cls(Path(recording), led["board_time_s"], led["level"], trajectory)

    def departures(self, led_track: Track) -> dict[str, float]:
        """The encoder's departure from rest on the video's clock, by EVENT_NAME; empty when the
        recording shows none (the pendulum was already swinging when it started)."""
        interval = float(np.median(np.diff(led_track.t)))
        self.alignment = align_blink_code(
            led_track.t + 0.5 * interval, lit_frames(led_track), self.led_times, self.led_levels, exposure_s=interval
        )
        offset = self.alignment.offset_s
        # The board recorded from its first event on; the encoder rests until its first edge.
        first = min(float(self.led_times[0]), float(self.encoder.times[0]))
        start = max(float(led_track.t[0]), first - offset)
        end = min(float(led_track.t[-1]), float(self.encoder.times[-1]) - offset)
        if end <= start:
            raise AnalysisError(f"the board recording {self.recording} does not overlap the video in time")
        times = np.arange(start, end, ENCODER_SAMPLE_S)
        angles = self.encoder.angle(times + offset)
        departure = departure_time(times, angles, np.zeros_like(angles))
        self.departure_board_s = None if departure is None else departure + offset
        return {} if departure is None else {EVENT_NAME: departure}

    def to_dict(self) -> dict[str, Any]:
        alignment = self.alignment
        return {
            "recording": str(self.recording),
            "offset_s": None if alignment is None else alignment.offset_s,
            "offset_interval_s": None if alignment is None else [alignment.low_s, alignment.high_s],
            "blink_agreement": None if alignment is None else alignment.agreement,
            "blink_transitions_used": None if alignment is None else alignment.transitions_used,
            "encoder_departure_board_s": self.departure_board_s,
        }


def lit_frames(led_track: Track) -> np.ndarray:
    """Whether the LED is lit in each frame: its peak above LIT_FRACTION of its typical peak."""
    if not np.any(led_track.valid):
        raise AnalysisError("the LED was never found in the video, so its blink cannot be read")
    typical = float(np.median(led_track.peak[led_track.valid]))
    return led_track.peak > LIT_FRACTION * typical
