"""What an analysis returns: the latency, how it was found, each method's estimate, and the tracks."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from analysis.cycles import CycleResolution
from analysis.misfit import MisfitReport
from analysis.sampling import SamplingBias
from analysis.readout import RollingShutter
from analysis.blobs import Roi, Track
from analysis.windows import WindowedLatency


@dataclass(frozen=True)
class MethodResult:
    """One estimator's latency (ms, positive when the sphere lags) and its 95 % interval, if it has one.

    seconds is the time the estimator itself took; details holds its diagnostics, JSON-ready.
    fit holds the estimator's own result object (for plots), left out of the JSON.
    """

    method: str
    latency_ms: float
    ci95_ms: tuple[float, float] | None
    model: str
    seconds: float
    details: dict[str, Any]
    fit: Any = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "latency_ms": self.latency_ms,
            "ci95_ms": list(self.ci95_ms) if self.ci95_ms is not None else None,
            "model": self.model,
            "seconds": self.seconds,
            **self.details,
        }


@dataclass(frozen=True)
class LatencyResult:
    """The measured latency (positive: the sphere lags the LED) and how it was obtained.

    latency_ms, ci95_ms and model are those of ``method``; ``methods`` holds every estimator run.
    roi_source says where the ROIs came from ("given" or "auto"); led_rule how the LED was told
    from the sphere. ambiguous is True when the whole number of periods in the latency could not
    be decided (see ``analysis.cycles``); a warning then says why. sampling says what the
    camera's sampling of the display may do to the latency (None where it could not be measured),
    checks how well the model fits (``analysis.misfit``), shutter the camera's readout given or
    bounded and the rows each blob was filmed on (``analysis.readout``); each method's latency and
    interval already allow for all three, and ``warnings`` says where any changed them. The tracks
    are dated by their rows where the readout was given.
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
    methods: dict[str, MethodResult]
    cycles: CycleResolution
    windowed: WindowedLatency | None
    diagnostics: dict[str, Any]
    led_track: Track = field(repr=False)
    sphere_track: Track = field(repr=False)
    sampling: SamplingBias | None = field(default=None, repr=False)
    checks: MisfitReport | None = None
    shutter: RollingShutter | None = None

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
            "methods": {name: result.to_dict() for name, result in self.methods.items()},
            "cycles": self.cycles.to_dict(),
            "windowed": self.windowed.to_dict() if self.windowed is not None else None,
            "sampling": None if self.sampling is None else self.sampling.to_dict(),
            "checks": None if self.checks is None else self.checks.to_dict(),
            "rolling_shutter": None if self.shutter is None else self.shutter.to_dict(),
            "diagnostics": dict(self.diagnostics),
        }
