"""How a video is analysed (`AnalysisOptions`), each option declared once with its unit, range,
default and help (`declared.setting`), and checked where it enters: a value outside its range is an
AnalysisError naming the range. `analyse` takes the options whole and hands `track` and `estimate`
the same object; the rig's `rig analyse` options, a sweep's [analysis] table and the docs' table
are made from these declarations, so a new option is one field here (and the code that reads it).
"""

from __future__ import annotations

from dataclasses import dataclass

from analysis.calibration import SIDES
from analysis.cycles import DEFAULT_LATENCY_RANGE_S
from analysis.errors import AnalysisError
from analysis.estimators.registry import ALL, DEFAULT_METHOD, methods
from declared import ANY, NON_NEGATIVE, POSITIVE, Flag, check, setting

ROI = tuple[int, int, int, int]


def _methods() -> tuple[str, ...]:
    """The registered estimators (a lab may register more) and "all"."""
    return (*methods(), ALL)


def _increasing(pair: tuple[float, float]) -> str | None:
    """LOW below HIGH."""
    return None if pair[0] < pair[1] else "LOW must be below HIGH"


@dataclass(frozen=True)
class AnalysisOptions:
    """How to analyse a video (see `analysis.analyse`); every field is checked when the options are made."""

    fps: float | None = setting(
        None, "frames per second", "camera frame rate, overriding the file's; needed for image folders", POSITIVE,
        unset="the file's", flag="--fps",
    )  # fmt: skip
    led_roi: ROI | None = setting(
        None, "pixels", "region the LED swings in, X,Y,W,H; give both regions or neither", NON_NEGATIVE,
        unset="found in the video", flag=Flag("--led-roi", metavar="X,Y,W,H"),
    )  # fmt: skip
    sphere_roi: ROI | None = setting(
        None, "pixels", "region the sphere moves in, X,Y,W,H", NON_NEGATIVE, unset="found in the video",
        flag=Flag("--sphere-roi", metavar="X,Y,W,H"),
    )  # fmt: skip
    led_side: str | None = setting(
        None, "", "the LED is the blob on this side", choices=SIDES,
        unset="told apart by refresh steps, saturation, size and side", flag="--led-side",
    )  # fmt: skip
    method: str = setting(DEFAULT_METHOD, "", "estimator, as listed below", choices=_methods, flag="--method")
    latency_range_ms: tuple[float, float] = setting(
        tuple(v * 1e3 for v in DEFAULT_LATENCY_RANGE_S), "ms", "latencies considered, to fix the whole number of swing periods",
        ANY, rule=_increasing, flag=Flag("--latency-range", metavar="LOW,HIGH"),
    )  # fmt: skip
    seed: int = setting(0, "", "random seed of the bayes sampler", NON_NEGATIVE, flag="--seed")
    display_hz: float | None = setting(
        None, "Hz", "the display's refresh rate, if known; it fixes how the camera samples it", POSITIVE,
        unset="looked for in the video", flag="--display-hz",
    )  # fmt: skip
    exposure_ms: float | None = setting(
        None, "ms", "the camera's exposure, if known", POSITIVE, unset="estimated from the LED's motion blur",
        flag="--exposure-ms",
    )  # fmt: skip
    readout_ms: float | None = setting(
        None, "ms", "the camera's rolling-shutter readout, top row to bottom row (0 for a global shutter), if known: "
        "each blob is then timed by its rows", NON_NEGATIVE, unset="any readout up to the frame interval is allowed for",
        flag="--readout-ms",
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, AnalysisError)

    @property
    def latency_range_s(self) -> tuple[float, float]:
        """The latencies considered, in seconds."""
        low, high = self.latency_range_ms
        return low / 1e3, high / 1e3
