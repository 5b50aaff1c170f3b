"""What an analysis returns: the latency, how it was found, and the tracks it came from."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from analysis.tracking import Roi, Track

# A latency within this fraction of a period from half a period is flagged as ambiguous: there the
# wrapped phase difference may have come from the other side (lead instead of lag).
AMBIGUITY_MARGIN = 0.1


def is_ambiguous(latency_s: float, period_s: float) -> bool:
    """Whether |latency| lies within AMBIGUITY_MARGIN periods of half a period."""
    return abs(latency_s) >= (0.5 - AMBIGUITY_MARGIN) * period_s


@dataclass(frozen=True)
class LatencyResult:
    """The measured latency (positive: the sphere lags the LED) and how it was obtained.

    roi_source says where the ROIs came from ("given" or "auto"); led_rule says how the LED was
    told from the sphere ("given", or "auto: brighter blob is the LED").
    """

    latency_ms: float
    ci95_ms: tuple[float, float] | None
    method: str
    model: str
    period_s: float
    fps: float
    frames: int
    frames_used: int
    ambiguous: bool
    warnings: list[str]
    led_roi: Roi
    sphere_roi: Roi
    roi_source: str
    led_rule: str
    led_track: Track = field(repr=False)
    sphere_track: Track = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (without the tracks)."""
        return {
            "latency_ms": self.latency_ms,
            "ci95_ms": list(self.ci95_ms) if self.ci95_ms is not None else None,
            "method": self.method,
            "model": self.model,
            "period_s": self.period_s,
            "fps": self.fps,
            "frames": self.frames,
            "frames_used": self.frames_used,
            "ambiguous": self.ambiguous,
            "warnings": list(self.warnings),
            "led_roi": self.led_roi.as_list(),
            "sphere_roi": self.sphere_roi.as_list(),
            "roi_source": self.roi_source,
            "led_rule": self.led_rule,
        }
